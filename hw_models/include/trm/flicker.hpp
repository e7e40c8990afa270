// Flicker at a fixed gaze: how visible the alternation of a frame pair is, weighted by the spatio-temporal CSF at
// the pair frequency (half the refresh rate: the rate at which TRM, BFI and interlace alternate their two frames).
//
// For a pair of luminance images Y_a, Y_b (one view, consecutive frames), the alternation contrast is Eq. 1 of the
// supplement, A(x, y) = (Y_a − Y_b) / (Y_a + Y_b) (0 where both are black): at fixed gaze each pixel flickers with
// this Michelson contrast at ν = refresh / 2 Hz. Its spatial spectrum Â(ρ) is weighted by S_st(|ρ|, ν)
// and the result pooled as a root mean square over the view:
//
//   V(refresh) = √2 · RMS_xy( F⁻¹{ Â(ρ) · S_f(|ρ|, refresh / 2) } )
//   S_f(ρ, ν)  = S_st(max(ρ, ρ_peak(ν)), ν)
//
// S_st is csf_spatiotemporal (Kelly-Daly). It is band-pass in ρ at every ν, falling to 0 at ρ = 0, but flicker of a
// uniform field is seen: at the temporal frequencies of flicker the loss of sensitivity at low spatial frequencies
// disappears (J. G. Robson, "Spatial and temporal contrast-sensitivity functions of the visual system", JOSA 56(8),
// 1966: above about 6 Hz the spatial CSF is low-pass). S_f therefore holds the surface's peak value below the peak
// frequency ρ_peak(ν), as Daly's visible differences predictor flattens its CSF below the peak for the same reason.
//
// √2 makes V = 1 the detection threshold of a flickering grating covering the view (a grating of contrast c at
// ρ has RMS c / √2 and is at threshold when c · S = 1); V < 1 is invisible by this model. The RMS is computed
// from the power spectrum (Parseval), accumulated over pairs into a radial histogram, so V is evaluated for any
// refresh rate without going back to the images: that gives the refresh rate above which the flicker stops being
// visible.
//
// Surround: the view sits in a dark field (an HMD's lens edge, a monitor's bezel), so the images are zero-padded
// before the transform (`Surround::Dark`): a uniformly flickering view is a flickering patch, its edges part of
// its spectrum, and the transform does not wrap the view onto itself. `Surround::Periodic` transforms the view as
// one period (analytic tests).
//
// Limits of the model: the Kelly-Daly surface is one adaptation luminance (Kelly measured it at 300 trolands) and
// foveal; it does not model the periphery's higher flicker sensitivity, nor the Ferry-Porter rise of the critical
// flicker frequency with luminance. Its temporal fall-off is steep: full-contrast flicker of a large field reaches
// threshold near a 24 Hz pair frequency (refresh ≈ 48 Hz), below the 50-60 Hz critical flicker frequency measured
// for large bright fields, so V under-states flicker at low refresh rates; the order between methods is the
// model's, the absolute threshold is optimistic.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace trm {

enum class Surround { Dark, Periodic };

// S_f(ρ, ν) above, for |ρ| cycles/deg (finite) and ν Hz (finite and > 0). Throws std::invalid_argument naming the
// argument.
double flicker_sensitivity(double rho_cpd, double nu_hz);

class FlickerSpectrum {
 public:
  // pixels_per_degree finite and > 0; throws std::invalid_argument naming it.
  explicit FlickerSpectrum(double pixels_per_degree, Surround surround = Surround::Dark);

  // Adds the alternation of one pair: luminance images (CV_64FC1, finite, >= 0) of one size; every pair added
  // must have the size of the first. Throws std::invalid_argument naming the argument.
  void add_pair(const cv::Mat& luma_a, const cv::Mat& luma_b);
  int pairs() const { return pairs_; }

  // V at `refresh_hz` (finite and > 0), the mean over the pairs' mean square; 0 before any pair.
  double visibility(double refresh_hz) const;
  // The lowest refresh rate in [min_hz, max_hz] (1 Hz steps) from which V stays below 1 up to max_hz; +inf when
  // V >= 1 at max_hz; min_hz when the flicker is invisible over the whole range. Throws std::invalid_argument
  // unless 0 < min_hz <= max_hz, both finite.
  double invisible_from_hz(double min_hz = 30.0, double max_hz = 480.0) const;

 private:
  double pixels_per_degree_;
  Surround surround_;
  cv::Size size_{};
  double bin_width_cpd_ = 0.0;
  std::vector<double> power_;  // Σ over pairs of |Â|² / (N_transform · N_view), by radial spatial frequency bin
  int pairs_ = 0;
};

}  // namespace trm
