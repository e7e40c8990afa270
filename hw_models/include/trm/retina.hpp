// The viewer's eye and what reaches its retina (DESIGN §8; paper Sec. 3 and Fig. 12; supplement §1.1): the panel's
// light over time (panel_light.hpp) integrated in the frame of an eye that fixates or pursues a target moving along x.
//
//   x_retina = x_screen − x_eye(t),   x_eye(t) = v_eye · ppd · (t − t_origin)      (pixels; x grows with the column)
//   R(x)     = 1/D ∫_0^D light(x + x_eye(t), t) dt                                 (D = K frames · T)
//
// The screen between pixel centres is the linear interpolation of the pixels, constant beyond the first and last
// (replicated edges), so a shifted row has no seam. R is a time average in linear light: for a still eye it is the
// mean of the frames' averages (Talbot-Plateau), and light the eye does not move over is never blurred.
//
// The time integral is taken in S sub-steps (`substeps`, the accuracy knob) spread over the lit part of each frame
// (the OLED on-time, the strobe window, or the whole frame under a held backlight: a dark part adds nothing). Within a
// step the panel light is integrated exactly (PanelLight::weights) and the eye is taken at the step's middle, so the
// only error is the eye's motion within a step, h = v_eye · ppd · lit time / S pixels:
//   * h above a pixel: each step lays down a sharp copy of an edge, a staircase in place of the ramp: error O(1/S);
//   * h below a pixel: the interpolated edge is a ramp over a pixel, the midpoint rule sees a continuous integrand:
//     error O(1/S²).
// docs/eye_model.md measures both and chooses kDefaultRetinaSubsteps.
//
// Images: CV_64F with any channel count (each channel alike), finite and >= 0. A scan line over time, an "x–t image",
// has one row per frame (K rows) and one column per pixel; a sequence of whole frames is a vector of same-size images.
#pragma once

#include "trm/panel_light.hpp"

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

namespace trm {

// Pixels per degree and field of view (per eye) of a viewing set-up.
struct Viewer {
  std::string name;
  double pixels_per_degree = 0.0;
  double fov_horizontal_deg = 0.0;  // 0: not stated (a custom viewer)
  double fov_vertical_deg = 0.0;
};

// "vive": 11.42 ppd, the green channel at the lens centre read from the headset's factory calibration (O. Kreylos,
//   "The Display Resolution of Head-mounted Displays", 2018, http://doc-ok.org/?p=1677); field of view per eye
//   101.16° × 111.58° as the OpenVR runtime reports it (https://risa2000.github.io/hmdgdb/hmd_cfgs/
//   Vive_Native_R90.html, "Left eye head FOV").
// "rift" (Oculus Rift CV1): 13.84 ppd, the runtime's 792.76 pixels per unit tangent at the centre times π/180, and
//   79.55° × 89.66° per eye (https://risa2000.github.io/hmdgdb/hmd_cfgs/OculusRiftCV1_Native_R90.html).
// "monitor": 56 ppd, the paper's Experiment 1 (Sec. 5: a 27" 2560×1440 ASUS ROG Swift at 75 cm), 43.5° × 25.3°
//   (that screen's width and height at that distance).
// Throws std::invalid_argument naming `name` and the presets for any other name.
Viewer viewer_preset(const std::string& name);
// A viewer of `pixels_per_degree` (finite and > 0; throws std::invalid_argument naming it), field of view not stated.
Viewer custom_viewer(double pixels_per_degree);

// Where the eye looks: a target moving at target_velocity_deg_s along x (negative: toward −x), and the eye's speed;
// or a target whose motion changes from frame to frame, given as its path, with the eye on it.
struct Gaze {
  double target_velocity_deg_s = 0.0;
  double eye_velocity_deg_s = 0.0;
  // When set: the target's position on the screen along x at time t (pixels; only x(t) − x(t_origin) counts), which
  // the eye follows exactly. It replaces both velocities in every integral (the moving frame at each sub-step's middle
  // is x(t) there, so the motion is piecewise at the eye's sub-frame steps); the velocities then hold the path's mean,
  // for what needs one number (captions, the Fourier view's window of visibility).
  std::function<double(double t_s)> path_px = {};

  // The eye holds still while the target moves (no drift: the Talbot-Plateau case).
  static Gaze fixation(double target_velocity_deg_s = 0.0);
  // Smooth pursuit with the lag of supplement Eq. 3 (eye_velocity_deg_s in pursuit.hpp).
  static Gaze pursuit(double target_velocity_deg_s);
  // The eye exactly on the target (the supplement's Fig. 1, right; the analytic hold-type blur cases).
  static Gaze perfect_pursuit(double target_velocity_deg_s);
  // A world point fixated while the head rotates: the vestibulo-ocular reflex, with pursuit, holds it still on the
  // retina whatever the head does, so the eye follows the point's display path frame by frame (trm/head_pose.hpp's
  // HeadPath::fixated_pixel gives it for the head-rotation scenes), with no lag. Throws std::invalid_argument naming
  // `path_px` when it is empty or `mean_velocity_deg_s` when it is not finite.
  static Gaze following(std::function<double(double t_s)> path_px, double mean_velocity_deg_s);
  // The target's velocity over the retina, target − eye: supplement Eq. 3's v_r for pursuit, 0 on a path.
  double target_retinal_velocity_deg_s() const { return target_velocity_deg_s - eye_velocity_deg_s; }
};
// Each Gaze factory throws std::invalid_argument naming `target_velocity_deg_s` when it is not finite.

// Sub-steps per frame: at the Vive's ppd and 90 Hz every step stays under a pixel of eye travel up to the fastest
// pursuit (80 deg/s) and a pursued edge within one 8-bit code of the exact image, on the OLED, a held and an LC panel
// (docs/eye_model.md). Take substeps_for_error for higher ppd or slower refresh.
inline constexpr int kDefaultRetinaSubsteps = 16;

// The sub-steps that keep the retinal error of a pursued unit-contrast edge at or below `max_error`, from the bound
// measured in docs/eye_model.md: with `sweep` the eye's travel in pixels over a frame's lit part
// (|v_eye| · ppd · lit time), the maximum error is about sweep / (16 S²), and under sweep / (10 S²) in every measured
// case, once steps are under a pixel (S >= sweep). Returns max(1, ⌈sweep⌉, ⌈√(sweep / (10 max_error))⌉). Content
// with sharper kinks than an interpolated edge (a one-pixel line has twice its slope change) needs √2 more. Throws
// std::invalid_argument naming the argument (max_error not in (0, 1), eye_velocity_deg_s not finite, ppd not finite
// and > 0).
int substeps_for_error(const PanelLight& light, const Viewer& viewer, double eye_velocity_deg_s, double max_error);

struct RetinaOptions {
  int substeps = kDefaultRetinaSubsteps;  // S >= 1
  double origin_s = 0.0;                  // t_origin: when x_eye = 0 (the retinal grid lies on the screen's)
  // For a scan line: which row it is of how many (rolling scan-out delays row y by y / rows · T).
  int row = 0;
  int rows = 1;
};

// The retinal image (time average, 1×N) of one scan line shown for K frames: `frames` K×N, row n the steady levels
// frame n drives (PanelLight's L). `previous` (1×N) is the LC state before frame 0 (at rest, for a second-order LC);
// empty: settled at frame 0.
// Throws std::invalid_argument naming the argument (empty or non-CV_64F `frames`, negative or non-finite levels,
// `previous` of another size or type, eye_velocity_deg_s not finite, substeps < 1, row outside [0, rows)).
cv::Mat retinal_row(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, double eye_velocity_deg_s,
                    const RetinaOptions& options = {}, const cv::Mat& previous = {});
// The same for the eye of `gaze`: its velocity, or its path (the path's values must be finite, else
// std::invalid_argument naming `gaze.path_px`).
cv::Mat retinal_row(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                    const RetinaOptions& options = {}, const cv::Mat& previous = {});

// The retinal image (time average) of whole frames, each row y delayed by its scan-out: same size and type as the
// frames. `previous`: the LC state before frame 0, empty for settled; `previous_rate`: a second-order LC's rate
// (1/s) there, empty for at rest (ignored by first-order models). Throws std::invalid_argument naming the argument.
cv::Mat retinal_image(const std::vector<cv::Mat>& frames, const PanelLight& light, const Viewer& viewer,
                      double eye_velocity_deg_s, const RetinaOptions& options = {}, const cv::Mat& previous = {},
                      const cv::Mat& previous_rate = {});

// The x–t image of the scan line in a frame of reference moving at frame_velocity_deg_s (0: the physical image,
// Fig. 12 column 1; the eye's velocity: the retinal image, column 2; the target's: the supplement's Fig. 1 right).
// (K·S)×N: row m is the mean light over [m, m + 1) · T / S (after the row's scan-out delay), at the frame's position
// at the middle of that interval. Uniform in time (S steps over the whole frame, lit or not), so rows are samples at
// S · refresh per second for a DFT. Same arguments and errors as retinal_row.
cv::Mat retinal_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, double frame_velocity_deg_s,
                   const RetinaOptions& options = {}, const cv::Mat& previous = {});
// retinal_xt in the frame of the eye of `gaze` (its velocity, or its path): the retinal x–t image, Fig. 12 column 2.
cv::Mat retinal_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                   const RetinaOptions& options = {}, const cv::Mat& previous = {});

// The supplement's x–t image for visual_difference_energy: retinal_xt in the frame that follows the target exactly,
// at its velocity or along its path (the energy applies the lag itself: pass it xt_samples_per_second and
// gaze.target_retinal_velocity_deg_s()).
cv::Mat target_frame_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                        const RetinaOptions& options = {}, const cv::Mat& previous = {});
// Rows per second of retinal_xt and target_frame_xt: S · refresh. Throws std::invalid_argument naming `substeps`.
double xt_samples_per_second(const PanelLight& light, int substeps);

// The reference: the same eye watching the object move continuously (no frames, no persistence). `profile` (1×N) is
// the object's scan line as it stands at t_origin; it moves at gaze.target_velocity_deg_s and the eye at
// gaze.eye_velocity_deg_s. Returns the time average over [t_begin, t_end] of the retinal light, exactly (the linear
// interpolant's integral over the swept interval, no sub-steps): the profile itself under perfect pursuit, a box blur
// of the swept length otherwise. Throws std::invalid_argument naming the argument (t_end <= t_begin or non-finite).
cv::Mat ideal_retinal_row(const cv::Mat& profile, const Viewer& viewer, const Gaze& gaze, double t_begin_s,
                          double t_end_s, double origin_s = 0.0);
// The same for whole images (every row alike).
cv::Mat ideal_retinal_image(const cv::Mat& image, const Viewer& viewer, const Gaze& gaze, double t_begin_s,
                            double t_end_s, double origin_s = 0.0);
// The ideal's x–t image in a frame moving at frame_velocity_deg_s: `rows` rows, row m the exact mean over
// [m, m + 1) · row_period_s. Throws std::invalid_argument naming the argument.
cv::Mat ideal_xt(const cv::Mat& profile, const Viewer& viewer, double target_velocity_deg_s,
                 double frame_velocity_deg_s, int rows, double row_period_s, double origin_s = 0.0);

// The 10–90 % width (pixels) of a monotone edge in a 1×N CV_64FC1 row: the distance between the first crossings of
// min + low·(max − min) and min + high·(max − min), each interpolated between samples. A linear ramp of width w gives
// (high − low)·w. Throws std::invalid_argument naming `row` (not 1×N CV_64FC1, N < 2, no edge) or the fractions
// (0 <= low < high <= 1).
double edge_width_px(const cv::Mat& row, double low = 0.1, double high = 0.9);
// Pixels to arcminutes on `viewer`.
double pixels_to_arcmin(double pixels, const Viewer& viewer);

}  // namespace trm
