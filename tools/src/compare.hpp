// `trm compare`: every display method on the same frames, through the same link and panel, measured with the same
// metrics (the paper's Table 1 with measured columns).
#pragma once

#include "options.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace trm::cli {

struct CompareOptions {
  PipelineOptions pipeline;          // scene, size, frames, encoder, panel, link; --method and --impl do not apply
  std::vector<std::string> methods;  // NAME or NAME:OPTION; empty: every registered method
  std::string viewer = "vive";       // the eye's pixels per degree (trm/retina.hpp presets: vive, rift, monitor)
  std::optional<double> ppd;         // pixels per degree instead of the viewer preset's (finite, > 0)
  int substeps = 0;                  // retinal sub-frame steps S; 0: kDefaultRetinaSubsteps
  std::optional<double> speed_deg_s; // the pursued target's speed (every motion of the scene scaled to it)
  // Throws std::invalid_argument with one clear message (an unknown method, one named twice, bad shared options).
  void validate() const;
  // The methods compared, in order: the asked ones, or every registered method.
  std::vector<std::string> chosen_methods() const;
};

// What one method measured. Fractions and percentages are against full-rate rendering of the same frames.
struct MethodMeasure {
  std::string method;
  std::int64_t views = 0;
  double pixels_rendered_saved_percent = 0.0;   // 100 (1 - rendered / full rate)
  double pixels_sent_saved_percent = 0.0;       // 100 (1 - sent / full rate)
  double mean_link_payload_bits = 0.0;          // per link frame
  std::uint64_t peak_link_wire_bits = 0;
  bool link_fits = true;
  double luminance_percent = 0.0;               // mean emitted luma against the full-rate emission's
  double flicker_contrast = 0.0;                // mean |Y_2k - Y_2k+1| / (Y_2k + Y_2k+1) over lit pixels and pairs
  double reference_flicker_contrast = 0.0;      // the same of the full-rate emission (motion alone alternates too)
  double mtcd = 0.0;                            // Kim et al. Eq. 6 on the emitted light's 8-bit sRGB encoding
  double reference_mtcd = 0.0;
  double mean_pair_psnr_db = 0.0;               // fixed gaze, against the full-rate reference pair; +inf: exact
  // The eye pursuing the scene's target along its scan line (supplement Eqs. 1-4 on the x-t image in the target's
  // frame, the pursuit lag of Eq. 3): the visual difference energy against the `full` method over the same link
  // (artefacts) and against the target moving continuously (what any frame-based display loses: hold-type blur,
  // judder).
  double energy_vs_full_rate = 0.0;
  double energy_vs_continuous = 0.0;
  double mean_pair_ssim = 0.0;                  // fixed gaze, against the full-rate reference pair (OpenCV quality)
  // Fixed gaze, trm/flicker.hpp: the stCSF-weighted alternation of eye 0's pairs at this refresh rate (1 = the
  // threshold of a view-filling flickering grating), and the refresh rate from which it is invisible (+inf: still
  // visible at 480 Hz).
  double flicker_visibility = 0.0;
  double flicker_invisible_from_hz = 0.0;
  // The 10-90 % width of the target's steepest edge on the retina of an eye pursuing it exactly, time-averaged over
  // the run (the hold-type blur: speed x the time a pixel is lit), in arcmin; NaN when the target's line has no
  // sharp edge (textures: the steepest step of the line wider than 3 pixels).
  double motion_blur_arcmin = 0.0;
  // Judder: temporal_alias_energy (visual_difference.hpp) of the target-frame x-t image sampled once per frame
  // (each frame's light integrated): where successive frames put the pursued target.
  double judder = 0.0;
  // The aliases beyond full rate's (temporal_alias_energy with the `full` method's image as the reference): the
  // pixel grid sweeping the retina, which every method shares, cancels.
  double judder_vs_full_rate = 0.0;
  std::int64_t pairs = 0;
  double seconds = 0.0;                         // wall time of this method's run
};

struct CompareResult {
  CompareOptions options;
  cv::Size size;
  double pixels_per_degree = 0.0;
  int scan_line = 0;                  // the row the eye model follows the target along
  double target_velocity_deg_s = 0.0; // horizontal speed of the pursued target (on a head path: its mean)
  double eye_velocity_deg_s = 0.0;    // pursuit: supplement Eq. 3; on a head path: its mean
  // The scenes whose motion is the head rotating (FrameSource::head_view): the eye fixates the world point at the
  // scan line's middle column at t = 0 and follows its display path through the head poses frame by frame
  // (trm/head_pose.hpp's HeadPath, Gaze::following: the vestibulo-ocular reflex holds it still on the retina). Other
  // scenes: the constant-speed pursuit of Eq. 3.
  bool gaze_follows_head = false;
  std::vector<double> gaze_path_px;   // on a head path: the fixated point's x at each frame's start, from its t = 0 place
  double gaze_rms_speed_deg_s = 0.0;  // on a head path: the RMS over frames of its speed within each frame
  double motion_scale = 1.0;          // the scene's motions scaled by this (--speed)
  int substeps = 0;
  double continuous_blur_arcmin = 0.0;  // motion_blur_arcmin of the target moving continuously (its own edge)
  int window_begin = 0, window_width = 0;  // the scan line's columns the figures show and the blur is measured in
  std::vector<MethodMeasure> methods;
  std::vector<cv::Mat> figures;  // per method: the Fig. 12 view (xt_figure.hpp), RGB CV_8UC3; empty: no x-t image
};

// The target an eye model pursues in a source at t = 0: the scene's global motion, else its fastest object, along the
// row through that object's centre; no motion (inputs, still scenes): velocity 0, the middle row, the whole line.
struct PursuedTarget {
  double velocity_px_s = 0.0;          // horizontal, signed
  int scan_line = 0;
  double left = 0.0, right = 0.0;      // the target's columns at t = 0
};
PursuedTarget pursued_target(const FrameSource& source);

// The file name of a method's figure: "fig12_" + the method with ':' as '-' + ".png".
std::string figure_name(const std::string& method);

// Runs every chosen method in turn; progress(done, total) after each view (total views over all methods).
CompareResult run_compare(const CompareOptions& options,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

// The table as the terminal shows it, as Markdown, as CSV (one row per method) and as JSON.
std::string compare_table(const CompareResult& result);
std::string compare_markdown(const CompareResult& result);
std::string compare_csv(const CompareResult& result);
nlohmann::ordered_json compare_json(const CompareResult& result);

}  // namespace trm::cli
