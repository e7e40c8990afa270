// What the viewer of a `trm sweep` point sees: the decoded drive codes of eye 0 through the panel's light over time
// and the eye model (panel_light.hpp, retina.hpp), pursuing the scene's target with the lag of supplement Eq. 3.
//
// A perceived sequence is (1) the retinal image of every frame pair 2k, 2k + 1 (RGB, the LC state carried across
// pairs), and (2) the x-t image of the scan line through the target in the target's frame (luma), the image the
// supplement's visual difference energy is defined on. Its error against another sequence is the PSNR of all the
// pairs together (psnr_srgb) and visual_difference_energy of the x-t images.
#pragma once

#include "trm/panel.hpp"
#include "trm/panel_light.hpp"
#include "trm/retina.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace trm::cli {

// The eye model's sub-frame steps every eye-model knob value is held to: converged far below what an 8-bit code
// shows at the sweep's sizes (docs/eye_model.md: error about sweep / (16 S^2)), and a multiple of every swept value, so
// that the exact x-t image's rows average onto a coarser one's.
inline constexpr int kExactEyeSubsteps = 256;

// How the eye watches the sweep's sequence.
struct EyeSetup {
  Panel panel;
  int output_bits = 8;
  PanelLight light;
  Viewer viewer;
  double target_velocity_deg_s = 0.0;
  double eye_velocity_deg_s = 0.0;   // supplement Eq. 3 (Gaze::pursuit)
  double retinal_velocity_deg_s = 0.0;
  int scan_line = 0;
  int rows = 1;
};

// The set-up for the pipeline's panel at refresh_hz on the Vive's viewer, pursuing `target_velocity_px_s` along
// `scan_line` of a view `rows` high.
EyeSetup eye_setup(const Panel& panel, int output_bits, double refresh_hz, double target_velocity_px_s, int scan_line,
                   int rows);

// One frame of eye 0 as decoded: its time index and drive codes (CV_16UC3).
struct ShownFrame {
  std::int64_t t = 0;
  cv::Mat drive_codes;
};

struct PerceivedSequence {
  int substeps = 0;
  std::vector<cv::Mat> pairs;  // retinal image of each complete pair, CV_64FC3
  cv::Mat xt;                  // (K S) x N luma, CV_64FC1
};

// The frames (in time order) through the eye at `substeps` sub-frame steps. Throws std::invalid_argument naming
// `frames` when it is empty or not in time order.
PerceivedSequence perceive(const std::vector<ShownFrame>& frames, const EyeSetup& setup, int substeps);

struct PerceivedError {
  double psnr_db = 0.0;            // +inf: identical
  double visual_difference = 0.0;  // 0: identical
};

// `seen` against `reference` (the same frames, substeps a divisor of the reference's: the reference's x-t rows are
// averaged onto seen's, each a mean of the light over the same interval). Throws std::invalid_argument when the two
// do not match.
PerceivedError perceived_error(const PerceivedSequence& seen, const PerceivedSequence& reference,
                               const EyeSetup& setup);

}  // namespace trm::cli
