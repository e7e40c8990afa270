#include "compare.hpp"
#include "elapsed.hpp"

#include "pipeline.hpp"
#include "xt_figure.hpp"

#include "trm/encoder_json.hpp"
#include "trm/flicker.hpp"
#include "trm/head_pose.hpp"
#include "trm/metrics.hpp"
#include "trm/mtcd.hpp"
#include "trm/panel_light.hpp"
#include "trm/retina.hpp"
#include "trm/visual_difference.hpp"
#include "trm/transfer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

// Luma alternation over a pair, |Y_a - Y_b| / (Y_a + Y_b), summed over the pixels lit in either frame (counted in
// `lit`): a pixel black in both neither flickers nor dilutes the figure.
double alternation_contrast_sum(const cv::Mat& luma_a, const cv::Mat& luma_b, double& lit) {
  double sum = 0.0;
  for (int y = 0; y < luma_a.rows; ++y) {
    const auto* a = luma_a.ptr<double>(y);
    const auto* b = luma_b.ptr<double>(y);
    for (int x = 0; x < luma_a.cols; ++x) {
      const double total = a[x] + b[x];
      if (total > 0.0) {
        sum += std::abs(a[x] - b[x]) / total;
        lit += 1.0;
      }
    }
  }
  return sum;
}

// Kim et al.'s MTCD is defined on display colour values: the 8-bit sRGB encoding of the light.
cv::Mat display_values(const cv::Mat& linear) { return to_encoded(linear, Transfer::Srgb) * 255.0; }

// The widest 10-90 % edge (pixels, as the scene renders it) that motion blur is measured on.
constexpr double kSharpEdgeMaxPx = 3.0;

// The running figures of one method's run, per view in slot order.
class MethodMeter {
 public:
  MethodMeter(const Panel& panel, int output_bits, int scan_line, double pixels_per_degree, double refresh_hz)
      : panel_(panel),
        output_bits_(output_bits),
        full_rate_(panel, output_bits),
        scan_line_(scan_line),
        refresh_hz_(refresh_hz),
        pairs_(panel),
        flicker_(pixels_per_degree) {}

  void add(const DecodedView& view) {
    const DecodedFrame& shown = *view.decoded;
    const FrameMeta& slot = view.slot;
    const double full_pixels = static_cast<double>(slot.full_width) * slot.full_height;
    ++views_;
    full_pixels_ += full_pixels;
    pixels_rendered_ += static_cast<double>(view.pixels_rendered);
    pixels_sent_ += view.sent ? static_cast<double>(view.sent->codes.total()) : 0.0;

    const cv::Mat reference = full_rate_(*view.linear_full);
    const cv::Mat luma_emitted = luma(shown.emitted_linear);
    const cv::Mat luma_reference = luma(reference);
    luma_sum_ += cv::sum(luma_emitted)[0];
    reference_luma_sum_ += cv::sum(luma_reference)[0];

    const cv::Mat display = display_values(shown.emitted_linear);
    const cv::Mat reference_display = display_values(reference);
    Eye& eye = eyes_[slot.eye];
    if (eye.t == slot.index - 1) {
      mtcd_sum_ += mtcd({eye.display, display});
      reference_mtcd_sum_ += mtcd({eye.reference_display, reference_display});
      ++mtcd_steps_;
      if (slot.index % 2 == 1) {
        flicker_sum_ += alternation_contrast_sum(eye.luma, luma_emitted, flicker_lit_);
        reference_flicker_sum_ += alternation_contrast_sum(eye.reference_luma, luma_reference, reference_flicker_lit_);
        if (slot.eye == 0) flicker_.add_pair(eye.luma, luma_emitted);
      }
    }
    if (const auto pair = pairs_.add(slot.eye, slot.index, shown.emitted_linear, reference)) {
      const double psnr = psnr_srgb(pair->perceived, pair->reference);
      ssim_sum_ += ssim_srgb(pair->perceived, pair->reference);
      ++pair_count_;
      if (std::isfinite(psnr)) {
        psnr_sum_ += psnr;
        ++finite_pairs_;
      }
    }
    if (slot.eye == 0) {
      levels_.push_back(luma(steady_levels(panel_, output_bits_, shown.drive_codes.row(scan_line_))));
      if (profile_.empty()) profile_ = luma(view.linear_full->row(scan_line_));
    }
    eye.t = slot.index;
    eye.luma = luma_emitted;
    eye.reference_luma = luma_reference;
    eye.display = display;
    eye.reference_display = reference_display;
  }

  // The scan line's x-t images (rows: frames of eye 0, steady levels the frames drive) and the scene's line at t = 0.
  cv::Mat levels() const { return stacked(levels_); }
  const cv::Mat& profile() const { return profile_; }

  void finish(MethodMeasure& m) const {
    m.views = views_;
    m.pixels_rendered_saved_percent = full_pixels_ > 0 ? 100.0 * (1.0 - pixels_rendered_ / full_pixels_) : 0.0;
    m.pixels_sent_saved_percent = full_pixels_ > 0 ? 100.0 * (1.0 - pixels_sent_ / full_pixels_) : 0.0;
    m.luminance_percent = reference_luma_sum_ > 0 ? 100.0 * luma_sum_ / reference_luma_sum_ : 0.0;
    m.flicker_contrast = flicker_lit_ > 0 ? flicker_sum_ / flicker_lit_ : 0.0;
    m.reference_flicker_contrast = reference_flicker_lit_ > 0 ? reference_flicker_sum_ / reference_flicker_lit_ : 0.0;
    m.mtcd = mtcd_steps_ > 0 ? mtcd_sum_ / mtcd_steps_ : 0.0;
    m.reference_mtcd = mtcd_steps_ > 0 ? reference_mtcd_sum_ / mtcd_steps_ : 0.0;
    m.pairs = pair_count_;
    m.flicker_visibility = flicker_.visibility(refresh_hz_);
    m.flicker_invisible_from_hz = flicker_.invisible_from_hz();
    m.mean_pair_ssim = pair_count_ > 0 ? ssim_sum_ / static_cast<double>(pair_count_) : 0.0;
    // Every pair exact: +inf, as psnr_srgb says of one exact pair.
    m.mean_pair_psnr_db = finite_pairs_ > 0 ? psnr_sum_ / static_cast<double>(finite_pairs_)
                                           : (pair_count_ > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  }

 private:
  struct Eye {
    std::int64_t t = -2;
    cv::Mat luma, reference_luma, display, reference_display;
  };
  static cv::Mat stacked(const std::vector<cv::Mat>& rows) {
    cv::Mat out;
    if (!rows.empty()) cv::vconcat(rows, out);
    return out;
  }

  const Panel& panel_;
  int output_bits_;
  FullRateEmission full_rate_;  // each view's full-rate reference
  int scan_line_;
  double refresh_hz_;
  PairTracker pairs_;
  FlickerSpectrum flicker_;
  std::vector<cv::Mat> levels_;
  cv::Mat profile_;
  std::map<int, Eye> eyes_;
  std::int64_t views_ = 0;
  double full_pixels_ = 0, pixels_rendered_ = 0, pixels_sent_ = 0;
  double luma_sum_ = 0, reference_luma_sum_ = 0;
  double flicker_sum_ = 0, reference_flicker_sum_ = 0, flicker_lit_ = 0, reference_flicker_lit_ = 0;
  double mtcd_sum_ = 0, reference_mtcd_sum_ = 0;
  std::int64_t mtcd_steps_ = 0;
  double psnr_sum_ = 0, ssim_sum_ = 0;
  std::int64_t pair_count_ = 0, finite_pairs_ = 0;
};

std::string number(double v, int digits) {
  if (std::isinf(v)) return "exact";
  if (std::isnan(v)) return "-";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

// Columns shared by the terminal table, Markdown and CSV: header and the cell of each method.
struct Column {
  const char* header;
  std::string (*cell)(const MethodMeasure&);
};

const std::vector<Column>& columns() {
  static const std::vector<Column> all = {
      {"method", [](const MethodMeasure& m) { return m.method; }},
      {"rendered saved %", [](const MethodMeasure& m) { return number(m.pixels_rendered_saved_percent, 1); }},
      {"sent saved %", [](const MethodMeasure& m) { return number(m.pixels_sent_saved_percent, 1); }},
      {"link Mbit/frame", [](const MethodMeasure& m) { return number(m.mean_link_payload_bits / 1e6, 3); }},
      {"luminance %", [](const MethodMeasure& m) { return number(m.luminance_percent, 1); }},
      {"flicker", [](const MethodMeasure& m) { return number(m.flicker_contrast, 4); }},
      {"flicker (full rate)", [](const MethodMeasure& m) { return number(m.reference_flicker_contrast, 4); }},
      {"flicker JND", [](const MethodMeasure& m) { return number(m.flicker_visibility, 3); }},
      {"flicker-free from Hz", [](const MethodMeasure& m) {
         return std::isinf(m.flicker_invisible_from_hz) ? std::string("> 480") : number(m.flicker_invisible_from_hz, 0);
       }},
      {"blur arcmin", [](const MethodMeasure& m) { return number(m.motion_blur_arcmin, 2); }},
      {"judder", [](const MethodMeasure& m) { return number(m.judder, 2); }},
      {"judder vs full rate", [](const MethodMeasure& m) { return number(m.judder_vs_full_rate, 2); }},
      {"MTCD", [](const MethodMeasure& m) { return number(m.mtcd, 3); }},
      {"MTCD (full rate)", [](const MethodMeasure& m) { return number(m.reference_mtcd, 3); }},
      {"pair PSNR dB", [](const MethodMeasure& m) { return number(m.mean_pair_psnr_db, 2); }},
      {"pair SSIM", [](const MethodMeasure& m) { return number(m.mean_pair_ssim, 4); }},
      {"energy vs full rate", [](const MethodMeasure& m) { return number(m.energy_vs_full_rate, 2); }},
      {"energy vs continuous", [](const MethodMeasure& m) { return number(m.energy_vs_continuous, 2); }},
  };
  return all;
}

}  // namespace

PursuedTarget pursued_target(const FrameSource& source) {
  PursuedTarget target;
  const Motion motion = source.motion(0);
  target.velocity_px_s = motion.global_velocity_px_s[0];
  target.scan_line = source.height() / 2;
  target.right = source.width();
  if (target.velocity_px_s == 0.0) {
    for (const MotionObject& object : motion.objects) {
      if (std::abs(object.velocity_px_s[0]) > std::abs(target.velocity_px_s)) {
        target.velocity_px_s = object.velocity_px_s[0];
        const double centre = object.bounds.y + 0.5 * object.bounds.height;
        target.scan_line = std::clamp(static_cast<int>(centre), 0, source.height() - 1);
        target.left = object.bounds.x;
        target.right = object.bounds.x + object.bounds.width;
      }
    }
  }
  return target;
}

std::string figure_name(const std::string& method) {
  std::string name = method;
  std::replace(name.begin(), name.end(), ':', '-');
  return "fig12_" + name + ".png";
}

std::vector<std::string> CompareOptions::chosen_methods() const {
  if (!methods.empty()) return methods;
  std::vector<std::string> all;
  for (const DisplayMethod& m : display_methods()) all.push_back(m.name);
  return all;
}

void CompareOptions::validate() const {
  pipeline.validate();
  if (ppd && !(std::isfinite(*ppd) && *ppd > 0.0)) {
    throw std::invalid_argument("--ppd must be a finite number of pixels per degree > 0");
  }
  if (substeps < 0) throw std::invalid_argument("--substeps must be >= 1 (leave it out for the default)");
  if (speed_deg_s) {
    if (!(std::isfinite(*speed_deg_s) && *speed_deg_s >= 0.0)) {
      throw std::invalid_argument("--speed must be a finite speed >= 0 deg/s");
    }
    if (!pipeline.input.empty()) {
      throw std::invalid_argument("--speed applies to the built-in scenes, not to --input (its motion is recorded)");
    }
  }
  try {
    (void)viewer_preset(viewer);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--viewer: ") + e.what());
  }
  std::set<std::string> seen;
  for (const std::string& spec : chosen_methods()) {
    try {
      check_display_method(spec, "reference");
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--methods: ") + e.what());
    }
    if (!seen.insert(spec).second) throw std::invalid_argument("--methods: '" + spec + "' is named twice");
  }
}

CompareResult run_compare(const CompareOptions& options,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress) {
  options.validate();
  CompareResult result;
  result.options = options;
  const std::vector<std::string> methods = options.chosen_methods();
  const std::int64_t frames = options.pipeline.frames > 0 ? options.pipeline.frames : options.pipeline.default_frames;
  const bool full_listed = std::find(methods.begin(), methods.end(), "full") != methods.end();
  const std::int64_t total = static_cast<std::int64_t>(methods.size() + (full_listed ? 0 : 1)) * frames *
                             (options.pipeline.encoder.stereo ? 2 : 1);
  std::int64_t done = 0;
  // The pursued target: the scene's global motion, else its fastest object; the eye follows it along the row
  // through its centre at t = 0. Inputs without known motion are watched at a fixed gaze.
  const std::unique_ptr<FrameSource> source = options.pipeline.open_source();
  PipelineOptions shown = options.pipeline;  // what every method runs on: the scene at the asked speed
  const PursuedTarget target = pursued_target(*source);
  double target_px_s = target.velocity_px_s;
  result.scan_line = target.scan_line;
  const double target_left = target.left, target_right = target.right;
  const Viewer viewer = options.ppd ? custom_viewer(*options.ppd) : viewer_preset(options.viewer);
  std::unique_ptr<FrameSource> scaled_source;  // the scene at the asked speed, when one is asked
  if (options.speed_deg_s) {
    if (target_px_s == 0.0) {
      throw std::invalid_argument("--speed: scene '" + options.pipeline.scene + "' has no moving target to set the "
                                  "speed of");
    }
    const double native_deg_s = std::abs(target_px_s) / viewer.pixels_per_degree;
    shown.motion_scale = *options.speed_deg_s / native_deg_s;
    target_px_s *= shown.motion_scale;
    result.motion_scale = shown.motion_scale;
    scaled_source = shown.open_source();  // the scene accepts the scale (throws its own message otherwise)
  }
  const FrameSource& scene = scaled_source ? *scaled_source : *source;
  result.pixels_per_degree = viewer.pixels_per_degree;
  result.target_velocity_deg_s = target_px_s / viewer.pixels_per_degree;
  result.substeps = options.substeps > 0 ? options.substeps : kDefaultRetinaSubsteps;
  const PanelLight light = panel_light(options.pipeline.panel, options.pipeline.refresh_hz);
  const double duration_s = static_cast<double>(frames) / options.pipeline.refresh_hz;
  Gaze gaze = Gaze::pursuit(result.target_velocity_deg_s);
  Gaze exact_pursuit = Gaze::perfect_pursuit(result.target_velocity_deg_s);
  double travel_px = target_px_s * duration_s;                                  // the target's, over the run
  double largest_step_px = std::abs(target_px_s) / options.pipeline.refresh_hz;  // its most in one frame
  if (const std::optional<HeadView> first = scene.head_view(0)) {
    // Poses through the frame after the last: the last frame's light, delayed by its row's scan-out, reaches into it.
    std::vector<Eigen::Quaterniond> poses;
    for (std::int64_t f = 0; f <= frames + 1; ++f) poses.push_back(scene.head_view(f)->orientation);
    const HeadPath head(std::move(poses), 1.0 / options.pipeline.refresh_hz);
    const PinholeView projection = first->projection;
    const cv::Point2d fixated(projection.centre().x, result.scan_line);
    const auto x_of = [head, projection, fixated](double t_s) {
      return head.fixated_pixel(fixated, t_s, projection).x;
    };
    double square_sum = 0.0;
    largest_step_px = 0.0;
    for (std::int64_t f = 0; f <= frames; ++f) {
      result.gaze_path_px.push_back(x_of(static_cast<double>(f) / options.pipeline.refresh_hz) - x_of(0.0));
      if (f == 0) continue;
      const double step = result.gaze_path_px[static_cast<std::size_t>(f)] - result.gaze_path_px[static_cast<std::size_t>(f - 1)];
      largest_step_px = std::max(largest_step_px, std::abs(step));
      square_sum += step * step;
    }
    travel_px = result.gaze_path_px.back();
    const double px_per_deg_s = viewer.pixels_per_degree / options.pipeline.refresh_hz;  // pixels per frame at 1 deg/s
    result.gaze_rms_speed_deg_s = frames > 0 ? std::sqrt(square_sum / static_cast<double>(frames)) / px_per_deg_s : 0.0;
    result.target_velocity_deg_s = travel_px / duration_s / viewer.pixels_per_degree;
    result.gaze_follows_head = true;
    gaze = Gaze::following(x_of, result.target_velocity_deg_s);
    exact_pursuit = gaze;
  }
  result.eye_velocity_deg_s = gaze.eye_velocity_deg_s;
  RetinaOptions retina;
  retina.substeps = result.substeps;
  retina.row = result.scan_line;
  retina.rows = source->height();
  const double xt_rate = xt_samples_per_second(light, result.substeps);
  const double lag = gaze.target_retinal_velocity_deg_s();
  cv::Mat profile;  // the scan line of the scene at t = 0: what moves continuously in the ideal reference
  // One method's run: its measures, and its scan line's x-t levels for the pursuit energies.
  const auto run_method = [&](const std::string& spec, cv::Mat& levels) {
    PipelineOptions run = shown;
    run.method = spec;
    // Every method is judged in linear light (DESIGN §9): the double-precision headset side for all of them.
    run.impl = "reference";
    run.impl_given = false;
    run.compare_reference = false;
    run.pixels_per_degree = viewer.pixels_per_degree;  // what a method that predicts pursuit (didyk) assumes
    if (run.link_preset.empty()) run.link_preset = "dp1.4";  // bandwidth per link frame for every method
    MethodMeter meter(run.panel, run.output_bits, result.scan_line, viewer.pixels_per_degree, run.refresh_hz);
    MethodMeasure measure;
    measure.method = spec;
    double payload_sum = 0.0;
    std::int64_t link_frames = 0;
    const auto start = std::chrono::steady_clock::now();
    const PipelineResult outcome = run_pipeline(
        run,
        [&](const DecodedView& view) {
          meter.add(view);
          result.size = cv::Size(view.slot.full_width, view.slot.full_height);
          if (progress) progress(++done, total);
        },
        [&](const link::LinkFrameUsage& usage) {
          payload_sum += static_cast<double>(usage.bits.payload_bits);
          ++link_frames;
        });
    measure.seconds = seconds_since(start);
    meter.finish(measure);
    levels = meter.levels();
    profile = meter.profile();
    measure.mean_link_payload_bits = link_frames > 0 ? payload_sum / static_cast<double>(link_frames) : 0.0;
    if (outcome.link) {
      measure.peak_link_wire_bits = outcome.link->summary.peak_wire_bits;
      measure.link_fits = outcome.link->summary.fits;
    }
    return measure;
  };
  // Full-rate rendering over the same link is the reference of the artefact energy, so that the link's quantisation,
  // which every method shares, is not counted as an artefact. It runs first, listed or not.
  cv::Mat full_levels;
  const MethodMeasure full_rate = run_method("full", full_levels);
  // The columns the figures show: the target's path over the run, centred; the blur is measured around the
  // steepest edge of the target's line at t = 0, over the monotone run of the line that holds it, widened by the
  // blur and shift a frame-based display can add (three frames of travel).
  const int line_width = profile.empty() ? 0 : profile.cols;
  result.window_width = std::min(192, line_width);
  const double path_centre = 0.5 * (target_left + target_right) + 0.5 * travel_px;
  result.window_begin =
      std::clamp(static_cast<int>(std::lround(path_centre)) - result.window_width / 2, 0,
                 std::max(0, line_width - result.window_width));
  int blur_begin = 0, blur_end = 0;      // [begin, end) of the line where the edge's width is measured
  int judder_begin = 0, judder_end = 0;  // the target's columns, with the same margin
  if (line_width >= 2) {
    const auto* line = profile.ptr<double>(0);
    const int search_begin = std::clamp(static_cast<int>(std::floor(target_left)) - 2, 0, line_width - 2);
    const int search_end = std::clamp(static_cast<int>(std::ceil(target_right)) + 2, search_begin + 1, line_width - 1);
    int edge = search_begin;
    for (int x = search_begin; x < search_end; ++x) {
      if (std::abs(line[x + 1] - line[x]) > std::abs(line[edge + 1] - line[edge])) edge = x;
    }
    const double rise = line[edge + 1] - line[edge];
    const double tolerance = 1e-3 * std::abs(rise);
    int begin = edge, end = edge + 1;
    while (begin > 0 && (line[begin] - line[begin - 1]) * (rise > 0 ? 1 : -1) >= -tolerance) --begin;
    while (end + 1 < line_width && (line[end + 1] - line[end]) * (rise > 0 ? 1 : -1) >= -tolerance) ++end;
    const int margin = static_cast<int>(std::ceil(3.0 * largest_step_px)) + 4;
    blur_begin = std::max(0, begin - margin);
    blur_end = std::min(line_width, end + 1 + margin);
    judder_begin = static_cast<int>(std::floor(target_left)) - margin;
    judder_end = static_cast<int>(std::ceil(target_right)) + margin;
  }
  const auto edge_arcmin = [&](const cv::Mat& row) {
    if (blur_end - blur_begin < 2) return std::numeric_limits<double>::quiet_NaN();
    try {
      return pixels_to_arcmin(edge_width_px(row.colRange(blur_begin, blur_end).clone()), viewer);
    } catch (const std::invalid_argument&) {
      return std::numeric_limits<double>::quiet_NaN();  // no edge on the target's line
    }
  };
  result.continuous_blur_arcmin = line_width >= 2 ? edge_arcmin(profile) : std::numeric_limits<double>::quiet_NaN();
  // A soft gradient of a texture is no edge to measure blur on: the widths are NaN unless the target's own edge is
  // sharp.
  if (!(result.continuous_blur_arcmin <= pixels_to_arcmin(kSharpEdgeMaxPx, viewer))) {
    blur_begin = blur_end = 0;
    result.continuous_blur_arcmin = std::numeric_limits<double>::quiet_NaN();
  }
  // Judder from frame to frame: one sample per frame (the frame's light integrated), so the panel's own pulse
  // within a frame, which every method shares, is not counted; what is left is where each frame puts the target.
  RetinaOptions per_frame = retina;
  per_frame.substeps = 1;
  // What every method is measured against, seen once: full rate's x-t images and the continuous motion's.
  cv::Mat full_rate_seen, full_rate_per_frame, continuous;
  if (full_levels.rows >= 2) {
    full_rate_seen = target_frame_xt(full_levels, light, viewer, gaze, retina);
    full_rate_per_frame = target_frame_xt(full_levels, light, viewer, gaze, per_frame);
    continuous = ideal_xt(profile, viewer, result.target_velocity_deg_s, result.target_velocity_deg_s,
                          full_rate_seen.rows, 1.0 / xt_rate);
  }
  for (const std::string& spec : methods) {
    cv::Mat levels;
    MethodMeasure measure = spec == "full" ? full_rate : run_method(spec, levels);
    if (spec == "full") levels = full_levels;
    if (levels.rows >= 2 && !full_rate_seen.empty()) {
      const cv::Mat seen = target_frame_xt(levels, light, viewer, gaze, retina);
      measure.energy_vs_full_rate =
          visual_difference_energy(seen, full_rate_seen, viewer.pixels_per_degree, xt_rate, lag);
      measure.energy_vs_continuous =
          visual_difference_energy(seen, continuous, viewer.pixels_per_degree, xt_rate, lag);
      // Only the target's own columns (in its frame they stay where it stood at t = 0): other objects on the line
      // move in that frame, and their motion is no alias.
      const cv::Mat per_frame_seen = target_frame_xt(levels, light, viewer, gaze, per_frame);
      const cv::Range target_columns(std::max(0, judder_begin), std::min(per_frame_seen.cols, judder_end));
      if (target_columns.size() >= 2) {
        const cv::Mat mine = per_frame_seen.colRange(target_columns).clone();
        const double rate = xt_samples_per_second(light, 1);
        measure.judder = temporal_alias_energy(mine, viewer.pixels_per_degree, rate, lag);
        measure.judder_vs_full_rate = temporal_alias_energy(mine, viewer.pixels_per_degree, rate, lag,
                                                            full_rate_per_frame.colRange(target_columns).clone());
      }
      measure.motion_blur_arcmin =
          edge_arcmin(retinal_row(levels, light, viewer, exact_pursuit, retina));
      const std::string eye_text = result.gaze_follows_head
                                       ? ", eye on a world point through the head poses (mean " +
                                             number(result.target_velocity_deg_s, 2) + " deg/s)"
                                       : ", target " + number(result.target_velocity_deg_s, 1) + " deg/s, eye " +
                                             number(gaze.eye_velocity_deg_s, 1) + " deg/s";
      XtFigureInput figure{spec + ": " + (options.pipeline.input.empty() ? options.pipeline.scene : options.pipeline.input) +
                               eye_text + ", " + number(options.pipeline.refresh_hz, 0) + " Hz, row " +
                               std::to_string(result.scan_line),
                           levels, light, viewer, gaze, retina, result.window_begin, result.window_width};
      result.figures.push_back(xt_figure(figure));
    } else {
      measure.motion_blur_arcmin = std::numeric_limits<double>::quiet_NaN();
      result.figures.emplace_back();
    }
    result.methods.push_back(std::move(measure));
  }
  return result;
}

std::string compare_table(const CompareResult& result) {
  std::vector<std::size_t> width;
  for (const Column& c : columns()) width.push_back(std::string(c.header).size());
  for (const MethodMeasure& m : result.methods) {
    for (std::size_t i = 0; i < columns().size(); ++i) width[i] = std::max(width[i], columns()[i].cell(m).size());
  }
  std::ostringstream out;
  const auto row = [&](const std::function<std::string(std::size_t)>& cell) {
    out << " ";
    for (std::size_t i = 0; i < columns().size(); ++i) {
      const std::string text = cell(i);
      out << " " << (i == 0 ? text + std::string(width[i] - text.size(), ' ')
                            : std::string(width[i] - text.size(), ' ') + text);
    }
    out << "\n";
  };
  row([](std::size_t i) { return std::string(columns()[i].header); });
  for (const MethodMeasure& m : result.methods) row([&](std::size_t i) { return columns()[i].cell(m); });
  return out.str();
}

std::string compare_markdown(const CompareResult& result) {
  std::ostringstream out;
  const PipelineOptions& p = result.options.pipeline;
  out << "# Display methods compared\n\n"
      << (p.input.empty() ? p.scene : p.input) << ", " << result.size.width << "x" << result.size.height << ", "
      << p.refresh_hz << " Hz, r = " << p.encoder.reduction << ", panel " << p.panel.name << ", link "
      << (p.link_preset.empty() ? "dp1.4" : p.link_preset) << ". Fractions against full-rate rendering of the same "
      << "frames; flicker and pair PSNR at a fixed gaze (Talbot-Plateau); the energies (supplement Eqs. 1-4) for an eye "
      << (result.gaze_follows_head
              ? "fixating the world point at the middle of row " + std::to_string(result.scan_line) +
                    " and following it through the head poses frame by frame (vestibulo-ocular reflex: no lag; mean " +
                    number(result.target_velocity_deg_s, 2) + " deg/s, RMS per frame " +
                    number(result.gaze_rms_speed_deg_s, 2) + " deg/s)"
              : "pursuing the target at " + number(result.target_velocity_deg_s, 2) + " deg/s along row " +
                    std::to_string(result.scan_line))
      << " at " << number(result.pixels_per_degree, 2) << " ppd, " << result.substeps << " sub-frame steps. "
      << "Flicker JND: the stCSF-weighted alternation at " << number(p.refresh_hz / 2.0, 1) << " Hz (1 = threshold of "
      << "a flickering grating filling the view; trm/flicker.hpp); blur: 10-90 % width of the target's steepest edge "
      << "under exact pursuit (the target moving continuously: " << number(result.continuous_blur_arcmin, 2)
      << " arcmin); judder: the energy of the temporal aliases in the target's frame (and of those beyond full rate's). Figures: fig12_<method>.png.\n\n|";
  for (const Column& c : columns()) out << " " << c.header << " |";
  out << "\n|";
  for (std::size_t i = 0; i < columns().size(); ++i) out << (i == 0 ? "---|" : "---:|");
  out << "\n";
  for (const MethodMeasure& m : result.methods) {
    out << "|";
    for (const Column& c : columns()) out << " " << c.cell(m) << " |";
    out << "\n";
  }
  return out.str();
}

std::string compare_csv(const CompareResult& result) {
  std::ostringstream out;
  out << "method,views,pixels_rendered_saved_percent,pixels_sent_saved_percent,mean_link_payload_bits,"
         "peak_link_wire_bits,link_fits,luminance_percent,flicker_contrast,reference_flicker_contrast,mtcd,"
         "reference_mtcd,pairs,mean_pair_psnr_db,mean_pair_ssim,energy_vs_full_rate,energy_vs_continuous,"
         "flicker_visibility,flicker_invisible_from_hz,motion_blur_arcmin,judder,judder_vs_full_rate,seconds\n";
  out.precision(10);
  for (const MethodMeasure& m : result.methods) {
    out << m.method << ',' << m.views << ',' << m.pixels_rendered_saved_percent << ',' << m.pixels_sent_saved_percent
        << ',' << m.mean_link_payload_bits << ',' << m.peak_link_wire_bits << ',' << (m.link_fits ? 1 : 0) << ','
        << m.luminance_percent << ',' << m.flicker_contrast << ',' << m.reference_flicker_contrast << ',' << m.mtcd
        << ',' << m.reference_mtcd << ',' << m.pairs << ','
        << (std::isinf(m.mean_pair_psnr_db) ? std::string("inf") : number(m.mean_pair_psnr_db, 6)) << ','
        << m.mean_pair_ssim << ',' << m.energy_vs_full_rate << ',' << m.energy_vs_continuous << ','
        << m.flicker_visibility << ',' << m.flicker_invisible_from_hz << ',' << m.motion_blur_arcmin << ',' << m.judder
        << ',' << m.judder_vs_full_rate << ',' << m.seconds << '\n';
  }
  return out.str();
}

nlohmann::ordered_json compare_json(const CompareResult& result) {
  const PipelineOptions& p = result.options.pipeline;
  nlohmann::ordered_json j;
  j["tool"] = "trm compare";
  j["parameters"] = {{"source", p.input.empty() ? p.scene : p.input},
                     {"size", {result.size.width, result.size.height}},
                     {"frames", p.frames > 0 ? p.frames : p.default_frames},
                     {"refresh_hz", p.refresh_hz},
                     {"motion_scale", result.motion_scale},
                     {"encoder", encoder_json(p.encoder)},
                     {"output_bits", p.output_bits},
                     {"sensitivity", p.sensitivity},
                     {"panel", p.panel},
                     {"link", p.link_preset.empty() ? "dp1.4" : p.link_preset},
                     {"seed", p.seed}};
  j["eye"] = {{"pixels_per_degree", result.pixels_per_degree},
              {"scan_line", result.scan_line},
              {"target_velocity_deg_s", result.target_velocity_deg_s},
              {"gaze", result.gaze_follows_head ? "head-pose fixation" : "pursuit"},
              {"eye_velocity_deg_s", result.eye_velocity_deg_s},
              {"substeps", result.substeps},
              {"continuous_blur_arcmin", std::isfinite(result.continuous_blur_arcmin)
                                             ? nlohmann::ordered_json(result.continuous_blur_arcmin)
                                             : nlohmann::ordered_json(nullptr)},
              {"window", {result.window_begin, result.window_width}}};
  if (result.gaze_follows_head) {
    j["eye"]["rms_speed_deg_s"] = result.gaze_rms_speed_deg_s;
    j["eye"]["path_px"] = result.gaze_path_px;
  }
  nlohmann::ordered_json methods = nlohmann::ordered_json::array();
  for (const MethodMeasure& m : result.methods) {
    const auto finite = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); };
    methods.push_back({{"method", m.method},
                       {"views", m.views},
                       {"pixels_rendered_saved_percent", m.pixels_rendered_saved_percent},
                       {"pixels_sent_saved_percent", m.pixels_sent_saved_percent},
                       {"mean_link_payload_bits", m.mean_link_payload_bits},
                       {"peak_link_wire_bits", m.peak_link_wire_bits},
                       {"link_fits", m.link_fits},
                       {"luminance_percent", m.luminance_percent},
                       {"flicker_contrast", m.flicker_contrast},
                       {"reference_flicker_contrast", m.reference_flicker_contrast},
                       {"mtcd", m.mtcd},
                       {"reference_mtcd", m.reference_mtcd},
                       {"pairs", m.pairs},
                       {"mean_pair_psnr_db", finite(m.mean_pair_psnr_db)},
                       {"pairs_exact", std::isinf(m.mean_pair_psnr_db)},
                       {"mean_pair_ssim", m.mean_pair_ssim},
                       {"energy_vs_full_rate", m.energy_vs_full_rate},
                       {"energy_vs_continuous", m.energy_vs_continuous},
                       {"flicker_visibility", m.flicker_visibility},
                       {"flicker_invisible_from_hz", finite(m.flicker_invisible_from_hz)},
                       {"motion_blur_arcmin", finite(m.motion_blur_arcmin)},
                       {"judder", m.judder},
                       {"judder_vs_full_rate", m.judder_vs_full_rate},
                       {"seconds", m.seconds}});
  }
  j["methods"] = methods;
  return j;
}

}  // namespace trm::cli
