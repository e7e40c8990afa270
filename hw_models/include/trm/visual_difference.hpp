// The supplement's spatio-temporal visual difference energy (§1.1, Eqs. 1, 2 and 4) between two renderings of one
// scan line over time. Images are x–t images: CV_64FC1, one row per time sample (K rows, spaced 1 / fps s), one
// column per pixel of the line (N columns, spaced 1 / ppd deg), luminance >= 0.
//
// Frame: x is measured in the frame that follows the pursued target (the supplement's Fig. 1, right, ideal
// pursuit). The real eye lags (Eq. 3), so that frame slides over the retina at v_r = retinal_velocity_deg_s(v):
// retinal position = x + v_r t. A caller whose images are already retinal passes v_r = 0.
//
//   Eq. 1  C(x, t)   = (L_a − L_b) / (L_a + L_b)                       (0 where L_a + L_b = 0)
//   Eq. 2  C_n(x, t) = F⁻¹{ F{C}(ρ, ν) · S_st(ρ, ν + ρ v_r) }
//   Eq. 4  E         = (Σ_x Σ_t |C_n(x, t)|^β)^(1/β),  β = 2.6
//
// In Eq. 2, ν is the temporal frequency of a grating travelling towards +x, cos 2π(ρx − νt): a grating of the
// target frame at (ρ, ν) is, on the retina, cos 2π(ρ x_ret − (ν + ρ v_r) t), so it flickers at ν + ρ v_r there.
// S_st is csf_spatiotemporal (Kelly-Daly, csf.hpp), which depends on |ρ| and |ν + ρ v_r| only. It is 0 at ρ = 0,
// so a difference uniform along the whole line (the ρ = 0 column, at any ν) adds nothing: full-field flicker needs
// its own measure.
//
// The transform is OpenCV's 2-D DFT over the whole image, so the image is one period in x and in t (pad it if its
// edges must not wrap). DFT bin (m, k) (row m, column k) holds e^{+2πi(ρ_k x + ν'_m t)} with ρ_k = k·ppd/N,
// ν'_m = m·fps/K for indices up to half the length and (k − N)·ppd/N, (m − K)·fps/K above it; Eq. 2's travelling
// frequency is ν = −ν'_m. An even length has a bin at exactly half the sampling rate holding the two aliases ±fs/2
// in equal parts (a sampled standing wave), so its weight is the mean of the weights of the two.
#pragma once

#include <opencv2/core.hpp>

namespace trm {

// Eq. 4's spatio-temporal pooling exponent, fitted to the ModelFest data (A. B. Watson, "Visual detection of
// spatial contrast patterns: evaluation of five simple models", Optics Express 6(1):12, 2000).
inline constexpr double kVisualDifferenceBeta = 2.6;

// Signed frequency of DFT bin `index` of a transform of `length` samples taken at `sample_rate` per unit:
// index·rate/length for index <= length/2, (index − length)·rate/length above (so half the rate, for an even
// length, is reported as +rate/2). Throws std::invalid_argument naming the argument for length < 1, index outside
// [0, length) or a sample rate that is not finite and > 0.
double dft_frequency(int index, int length, double sample_rate);

// Eq. 1 on two same-size x–t images of luminance (CV_64FC1, finite, >= 0). Throws std::invalid_argument naming
// `l_a` or `l_b`.
cv::Mat contrast_difference(const cv::Mat& l_a, const cv::Mat& l_b);

// Eq. 2's weight S_st(|ρ|, |ν + ρ v_r|) for every bin of a K×N DFT (`size` = cv::Size(N, K)), in OpenCV's layout
// (bin (m, k) at row m, column k, no quadrant shift): CV_64FC1, the same for a bin and its conjugate, so a real
// image stays real. For Fourier-view plots. Throws std::invalid_argument naming `size`,
// `pixels_per_degree`, `samples_per_second` or `retinal_velocity_deg_s`.
cv::Mat stcsf_weights(cv::Size size, double pixels_per_degree, double samples_per_second,
                      double retinal_velocity_deg_s);

// Eq. 2: the stCSF-normalised contrast C_n of a contrast x–t image (CV_64FC1, finite), CV_64FC1 of its size.
// Throws std::invalid_argument naming the argument.
cv::Mat csf_weighted_contrast(const cv::Mat& contrast, double pixels_per_degree, double samples_per_second,
                              double retinal_velocity_deg_s);

// Eq. 4 over every sample of a CV_64FC1 image (finite); 0 for an all-zero image. Throws std::invalid_argument
// naming `normalised_contrast` or `beta` (finite and > 0).
double pooled_energy(const cv::Mat& normalised_contrast, double beta = kVisualDifferenceBeta);

// Eqs. 1, 2 and 4: the visual difference energy between renderings a and b. Symmetric in a and b, 0 when they are
// equal. Throws std::invalid_argument naming the argument (sizes differ, empty or non-CV_64FC1 images, negative or
// non-finite luminance, ppd or fps not finite and > 0, v_r not finite).
double visual_difference_energy(const cv::Mat& l_a, const cv::Mat& l_b, double pixels_per_degree,
                                double samples_per_second, double retinal_velocity_deg_s);

// Judder: the energy of what changes over time in an x–t image taken in the target's frame. Continuous motion
// pursued in that frame is still, so this is the energy of the temporal aliases a frame-based display adds (the
// replicas of Fig. 12's Fourier view, off the ν = 0 line), through Eqs. 2 and 4 at the lag's retinal velocity. The
// contrast is the change against each column's time average l̄ in units of the image's mean luminance L̄
// (Weber contrast at the region's adaptation level), C = (l − l̄) / L̄, rather than Eq. 1's (l − l̄) / (l + l̄): Eq. 1
// divides by the local luminance, which on a dark background turns the sub-pixel phase differences in an edge's
// dark tail into contrasts near 1. 0 for a still or a black image. Uniform flicker (ρ = 0) adds nothing, as in
// Eq. 2. With a `reference` (same size), the aliases l has beyond the reference's: the changing part of the
// reference is subtracted from l's before weighting (a display's own aliases, such as a pixel grid moving over the
// retina, cancel; 0 when l and the reference are equal). Same arguments and errors as visual_difference_energy.
double temporal_alias_energy(const cv::Mat& l, double pixels_per_degree, double samples_per_second,
                             double retinal_velocity_deg_s, const cv::Mat& reference = {});

}  // namespace trm
