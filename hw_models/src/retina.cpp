// The eye's retinal image of a panel's light: sub-stepped integration in a moving frame, and the exact ideal motion.
#include "trm/retina.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "perception_checks.hpp"
#include "trm/pursuit.hpp"

namespace trm {

namespace {

using perception_detail::number_text;
using perception_detail::reject;
using perception_detail::require_finite;
using perception_detail::require_positive;

// 27" 16:9 at 75 cm (paper Sec. 5): width 27·16/√337 in, height 27·9/√337 in.
constexpr double kInch = 2.54;
constexpr double kMonitorDistanceCm = 75.0;

double monitor_fov_deg(double side_in) {
  return 2.0 * std::atan(side_in * kInch / 2.0 / kMonitorDistanceCm) * 180.0 / std::numbers::pi;
}

void require_substeps(const char* where, int substeps) {
  if (substeps < 1) reject(where, "substeps", "must be >= 1, got " + std::to_string(substeps));
}

// Levels are light: CV_64F, finite, >= 0.
void require_levels(const char* where, const char* argument, const cv::Mat& levels) {
  if (levels.empty()) reject(where, argument, "must not be empty");
  if (levels.depth() != CV_64F) reject(where, argument, "must be CV_64F");
  for (int y = 0; y < levels.rows; ++y) {
    const double* row = levels.ptr<double>(y);
    for (int i = 0; i < levels.cols * levels.channels(); ++i) {
      if (!(std::isfinite(row[i]) && row[i] >= 0.0)) {
        reject(where, argument, "must hold finite levels >= 0, got " + number_text(row[i]));
      }
    }
  }
}

// One scan line of n pixels with c interleaved channels.
struct Line {
  int n = 0;
  int c = 1;
};

// The line at x + shift, linear between pixel centres, constant beyond the ends.
double sample(const double* src, Line line, int j, int ch, double shift_floor, double fraction) {
  const double p = j + shift_floor;
  if (p < 0.0) return src[ch];
  if (p >= line.n - 1) return src[static_cast<std::size_t>(line.n - 1) * line.c + ch];
  const auto i = static_cast<std::size_t>(p);
  const double a = src[i * line.c + ch];
  const double b = src[(i + 1) * line.c + ch];
  return a + (b - a) * fraction;
}

// dst(x) += weight · src(x + shift) for every pixel x of the line.
void add_shifted(const double* src, Line line, double shift, double weight, double* dst) {
  if (weight == 0.0) return;
  // Beyond a line's length every sample is an end pixel; the clamp keeps floor() in range.
  shift = std::clamp(shift, -static_cast<double>(line.n + 1), static_cast<double>(line.n + 1));
  const double shift_floor = std::floor(shift);
  const double fraction = shift - shift_floor;
  const int offset = static_cast<int>(shift_floor);
  // Pixels whose sample falls between two pixel centres, j + offset in [0, n − 2], run as one flat loop over
  // channels (the same arithmetic as sample(), so the edges and the interior agree bit for bit).
  const int interior_begin = std::clamp(-offset, 0, line.n);
  const int interior_end = std::clamp(line.n - 1 - offset, interior_begin, line.n);
  const auto edge = [&](int j) {
    for (int ch = 0; ch < line.c; ++ch) {
      dst[static_cast<std::size_t>(j) * line.c + ch] += weight * sample(src, line, j, ch, shift_floor, fraction);
    }
  };
  for (int j = 0; j < interior_begin; ++j) edge(j);
  const std::ptrdiff_t stride = line.c;
  const double* a = src + static_cast<std::ptrdiff_t>(interior_begin + offset) * stride;
  const double* b = a + stride;
  double* out = dst + static_cast<std::ptrdiff_t>(interior_begin) * stride;
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(interior_end - interior_begin) * stride;
  for (std::ptrdiff_t q = 0; q < count; ++q) out[q] += weight * (a[q] + (b[q] - a[q]) * fraction);
  for (int j = interior_end; j < line.n; ++j) edge(j);
}

// ∫_{p0}^{p1} of the line's interpolant (channel ch), p0 <= p1, each cell's part in closed form.
double interpolant_integral(const double* src, Line line, int ch, double p0, double p1) {
  const auto at = [&](int i) { return src[static_cast<std::size_t>(i) * line.c + ch]; };
  const double last = line.n - 1;
  double sum = 0.0;
  if (p0 < 0.0) sum += at(0) * (std::min(p1, 0.0) - p0);
  if (p1 > last) sum += at(line.n - 1) * (p1 - std::max(p0, last));
  const double lo = std::max(p0, 0.0);
  const double hi = std::min(p1, last);
  for (int i = static_cast<int>(std::floor(lo)); i < line.n - 1 && i < hi; ++i) {
    const double u0 = std::max(lo, static_cast<double>(i));
    const double u1 = std::min(hi, static_cast<double>(i + 1));
    if (u1 <= u0) continue;
    // ∫ f_i + (f_{i+1} − f_i)(u − i) du, the quadratic part as (u1 − u0)(u1 + u0 − 2i) / 2 to keep short spans exact.
    sum += at(i) * (u1 - u0) + (at(i + 1) - at(i)) * (u1 - u0) * (u1 + u0 - 2.0 * i) / 2.0;
  }
  return sum;
}

// dst(x) = mean over shifts u in [c0, c1] of src(x + u).
void mean_over_shifts(const double* src, Line line, double c0, double c1, double* dst) {
  const double lo = std::min(c0, c1);
  const double hi = std::max(c0, c1);
  for (int j = 0; j < line.n; ++j) {
    for (int ch = 0; ch < line.c; ++ch) {
      double value = 0.0;
      if (hi > lo) {
        value = interpolant_integral(src, line, ch, j + lo, j + hi) / (hi - lo);
      } else {
        const double shift_floor = std::floor(std::clamp(lo, -line.n - 1.0, line.n + 1.0));
        value = sample(src, line, j, ch, shift_floor, std::clamp(lo, -line.n - 1.0, line.n + 1.0) - shift_floor);
      }
      dst[static_cast<std::size_t>(j) * line.c + ch] = value;
    }
  }
}

// Where the moving frame of reference (eye or target) stands at time t, in pixels from where it stood at t_origin:
// at a constant velocity, or along a path sampled where the step asks.
class FrameMotion {
 public:
  FrameMotion(double velocity_px_s, double origin_s) : velocity_px_s_(velocity_px_s), origin_s_(origin_s) {}
  FrameMotion(const char* where, const std::function<double(double)>& path_px, double origin_s)
      : where_(where), path_px_(&path_px), origin_s_(origin_s), origin_px_(at(origin_s)) {}

  double shift(double t_s) const { return path_px_ ? at(t_s) - origin_px_ : velocity_px_s_ * (t_s - origin_s_); }

 private:
  double at(double t_s) const {
    const double x = (*path_px_)(t_s);
    if (!std::isfinite(x)) reject(where_, "gaze.path_px", "must give finite positions, got " + number_text(x));
    return x;
  }

  const char* where_ = "";
  const std::function<double(double)>* path_px_ = nullptr;
  double velocity_px_s_ = 0.0;
  double origin_s_ = 0.0;
  double origin_px_ = 0.0;
};

// How a pass lays its sub-steps and where it writes them.
enum class Steps {
  Lit,     // S steps over the lit window of each frame, all summed into out_rows[0] as a time average
  Uniform  // S steps over the whole frame, step m of the sequence into out_rows[m] as its mean
};

// One scan line through K frames: the panel light of each step (exact), shifted by the moving frame's position at
// the step's middle.
void line_pass(const std::vector<const double*>& frames, Line line, const double* previous,
               const double* previous_rate, const PanelLight& light, const FrameMotion& motion, double delay_s,
               int substeps, Steps steps,
               const std::vector<double*>& out_rows) {
  const double period = light.frame_period_s();
  const auto frame_count = static_cast<int>(frames.size());
  const std::size_t samples = static_cast<std::size_t>(line.n) * line.c;
  std::vector<double> state(previous ? previous : frames[0], (previous ? previous : frames[0]) + samples);
  const bool has_history = light.has_lc_state();
  // The level-dependent response gives every pixel its own segment (drive, τ): its light over a step is summed per
  // pixel first, then shifted once.
  const bool per_pixel = light.lc_response().has_value();
  // The second-order LC also carries each pixel's rate (from rest at the start), with weights shared by all pixels.
  const bool second_order = light.lc_second_order().has_value();
  std::vector<double> rate(second_order ? samples : 0, 0.0);
  if (second_order && previous_rate) std::copy(previous_rate, previous_rate + samples, rate.begin());
  std::vector<LcSegment> segments(per_pixel ? samples : 0);
  std::vector<double> step_light(per_pixel ? samples : 0);
  // With shared weights an overdriven frame's light is still linear in its drive, which differs per pixel.
  const bool overdriven = light.config().overdrive && !per_pixel;
  std::vector<double> drives(overdriven ? samples : 0);
  const double begin = steps == Steps::Lit ? light.window_begin_s() : 0.0;
  const double end = steps == Steps::Lit ? light.window_end_s() : period;
  for (int f = 0; f < frame_count; ++f) {
    for (std::size_t i = 0; i < segments.size(); ++i) segments[i] = light.segment(state[i], frames[f][i]);
    for (std::size_t i = 0; i < drives.size(); ++i) {
      drives[i] = light.drive(LcMotion{state[i], second_order ? rate[i] : 0.0}, frames[f][i]);
    }
    const double* driven = overdriven ? drives.data() : frames[f];
    for (int k = 0; k < substeps; ++k) {
      const double t0 = begin + (end - begin) * k / substeps;
      const double t1 = k + 1 == substeps ? end : begin + (end - begin) * (k + 1) / substeps;
      const double middle = delay_s + f * period + (t0 + t1) / 2.0;
      const double shift = motion.shift(middle);
      double* dst = steps == Steps::Lit ? out_rows[0] : out_rows[static_cast<std::size_t>(f) * substeps + k];
      const double scale = steps == Steps::Lit ? 1.0 / (frame_count * period) : 1.0 / (t1 - t0);
      if (per_pixel) {
        for (std::size_t i = 0; i < samples; ++i) {
          const LightWeights w = light.weights(t0, t1, segments[i].tau_s);
          step_light[i] = w.level * segments[i].drive + w.previous * state[i];
        }
        add_shifted(step_light.data(), line, shift, scale, dst);
        continue;
      }
      const LightWeights w = light.weights(t0, t1);
      add_shifted(driven, line, shift, w.level * scale, dst);
      if (has_history) add_shifted(state.data(), line, shift, w.previous * scale, dst);
      if (second_order) add_shifted(rate.data(), line, shift, w.previous_rate * scale, dst);
    }
    if (second_order) {
      for (std::size_t i = 0; i < samples; ++i) {
        const LcMotion next = light.end_state(LcMotion{state[i], rate[i]}, frames[f][i]);
        state[i] = next.level;
        rate[i] = next.rate_per_s;
      }
    } else if (has_history) {
      for (std::size_t i = 0; i < samples; ++i) state[i] = light.end_state(state[i], frames[f][i]);
    }
  }
}

// The common checks of the scan-line entry points; returns the line's shape.
Line check_scan_line(const char* where, const cv::Mat& frames, const Viewer& viewer, double velocity,
                     const char* velocity_name, const RetinaOptions& options, const cv::Mat& previous) {
  require_levels(where, "frames", frames);
  require_positive(where, "viewer.pixels_per_degree", viewer.pixels_per_degree);
  require_finite(where, velocity_name, velocity);
  require_finite(where, "options.origin_s", options.origin_s);
  require_substeps(where, options.substeps);
  if (options.rows < 1) reject(where, "options.rows", "must be >= 1, got " + std::to_string(options.rows));
  if (options.row < 0 || options.row >= options.rows) {
    reject(where, "options.row", "must be in [0, rows), got " + std::to_string(options.row));
  }
  if (!previous.empty()) {
    if (previous.rows != 1 || previous.cols != frames.cols || previous.type() != frames.type()) {
      reject(where, "previous", "must be one row of the frames' width and type");
    }
    require_levels(where, "previous", previous);
  }
  return Line{frames.cols, frames.channels()};
}

// `path_px`: the moving frame's path, or null for the constant velocity_deg_s.
cv::Mat scan_line_pass(const char* where, const cv::Mat& frames, const PanelLight& light, const Viewer& viewer,
                       double velocity_deg_s, const std::function<double(double)>* path_px, const char* velocity_name,
                       const RetinaOptions& options, const cv::Mat& previous, Steps steps) {
  const Line line = check_scan_line(where, frames, viewer, velocity_deg_s, velocity_name, options, previous);
  const FrameMotion motion = path_px ? FrameMotion(where, *path_px, options.origin_s)
                                     : FrameMotion(velocity_deg_s * viewer.pixels_per_degree, options.origin_s);
  std::vector<const double*> rows;
  for (int f = 0; f < frames.rows; ++f) rows.push_back(frames.ptr<double>(f));
  const int out_rows = steps == Steps::Lit ? 1 : frames.rows * options.substeps;
  cv::Mat out = cv::Mat::zeros(out_rows, frames.cols, frames.type());
  std::vector<double*> out_ptrs;
  for (int m = 0; m < out_rows; ++m) out_ptrs.push_back(out.ptr<double>(m));
  line_pass(rows, line, previous.empty() ? nullptr : previous.ptr<double>(0), nullptr, light, motion,
            light.row_delay_s(options.row, options.rows), options.substeps, steps, out_ptrs);
  return out;
}

void check_ideal(const char* where, const cv::Mat& profile, const Viewer& viewer, double target, double frame,
                 const char* frame_name) {
  require_levels(where, "profile", profile);
  require_positive(where, "viewer.pixels_per_degree", viewer.pixels_per_degree);
  require_finite(where, "target_velocity_deg_s", target);
  require_finite(where, frame_name, frame);
}

}  // namespace

Viewer viewer_preset(const std::string& name) {
  if (name == "vive") return {"vive", 11.42, 101.16, 111.58};
  if (name == "rift") return {"rift", 792.76 * std::numbers::pi / 180.0, 79.55, 89.66};
  if (name == "monitor") {
    const double diagonal = std::sqrt(16.0 * 16.0 + 9.0 * 9.0);
    return {"monitor", 56.0, monitor_fov_deg(27.0 * 16.0 / diagonal), monitor_fov_deg(27.0 * 9.0 / diagonal)};
  }
  reject("viewer_preset", "name", "must be 'vive', 'rift' or 'monitor', got '" + name + "'");
}

Viewer custom_viewer(double pixels_per_degree) {
  require_positive("custom_viewer", "pixels_per_degree", pixels_per_degree);
  return {"ppd:" + number_text(pixels_per_degree), pixels_per_degree, 0.0, 0.0};
}

Gaze Gaze::fixation(double target_velocity_deg_s) {
  require_finite("Gaze::fixation", "target_velocity_deg_s", target_velocity_deg_s);
  return {target_velocity_deg_s, 0.0};
}

Gaze Gaze::pursuit(double target_velocity_deg_s) {
  return {target_velocity_deg_s, trm::eye_velocity_deg_s(target_velocity_deg_s)};
}

Gaze Gaze::perfect_pursuit(double target_velocity_deg_s) {
  require_finite("Gaze::perfect_pursuit", "target_velocity_deg_s", target_velocity_deg_s);
  return {target_velocity_deg_s, target_velocity_deg_s};
}

Gaze Gaze::following(std::function<double(double t_s)> path_px, double mean_velocity_deg_s) {
  if (!path_px) reject("Gaze::following", "path_px", "must be a path (got none)");
  require_finite("Gaze::following", "mean_velocity_deg_s", mean_velocity_deg_s);
  return {mean_velocity_deg_s, mean_velocity_deg_s, std::move(path_px)};
}

int substeps_for_error(const PanelLight& light, const Viewer& viewer, double eye_velocity_deg_s, double max_error) {
  constexpr const char* kWhere = "substeps_for_error";
  require_positive(kWhere, "viewer.pixels_per_degree", viewer.pixels_per_degree);
  require_finite(kWhere, "eye_velocity_deg_s", eye_velocity_deg_s);
  if (!(max_error > 0.0 && max_error < 1.0)) {
    reject(kWhere, "max_error", "must be in (0, 1), got " + number_text(max_error));
  }
  const double sweep = std::abs(eye_velocity_deg_s) * viewer.pixels_per_degree *
                       (light.window_end_s() - light.window_begin_s());
  // Above a few million steps per frame the caller wants a closed form, not this integrator.
  constexpr double kMostSubsteps = 1 << 22;
  const double steps = std::max({1.0, std::ceil(sweep), std::ceil(std::sqrt(sweep / (10.0 * max_error)))});
  return static_cast<int>(std::min(steps, kMostSubsteps));
}

cv::Mat retinal_row(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, double eye_velocity_deg_s,
                    const RetinaOptions& options, const cv::Mat& previous) {
  return scan_line_pass("retinal_row", frames, light, viewer, eye_velocity_deg_s, nullptr, "eye_velocity_deg_s",
                        options, previous, Steps::Lit);
}

cv::Mat retinal_row(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                    const RetinaOptions& options, const cv::Mat& previous) {
  return scan_line_pass("retinal_row", frames, light, viewer, gaze.eye_velocity_deg_s,
                        gaze.path_px ? &gaze.path_px : nullptr, "gaze.eye_velocity_deg_s", options, previous,
                        Steps::Lit);
}

cv::Mat retinal_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, double frame_velocity_deg_s,
                   const RetinaOptions& options, const cv::Mat& previous) {
  return scan_line_pass("retinal_xt", frames, light, viewer, frame_velocity_deg_s, nullptr, "frame_velocity_deg_s",
                        options, previous, Steps::Uniform);
}

cv::Mat retinal_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                   const RetinaOptions& options, const cv::Mat& previous) {
  return scan_line_pass("retinal_xt", frames, light, viewer, gaze.eye_velocity_deg_s,
                        gaze.path_px ? &gaze.path_px : nullptr, "gaze.eye_velocity_deg_s", options, previous,
                        Steps::Uniform);
}

cv::Mat target_frame_xt(const cv::Mat& frames, const PanelLight& light, const Viewer& viewer, const Gaze& gaze,
                        const RetinaOptions& options, const cv::Mat& previous) {
  return scan_line_pass("target_frame_xt", frames, light, viewer, gaze.target_velocity_deg_s,
                        gaze.path_px ? &gaze.path_px : nullptr, "gaze.target_velocity_deg_s", options, previous,
                        Steps::Uniform);
}

double xt_samples_per_second(const PanelLight& light, int substeps) {
  require_substeps("xt_samples_per_second", substeps);
  return substeps * light.config().refresh_hz;
}

cv::Mat retinal_image(const std::vector<cv::Mat>& frames, const PanelLight& light, const Viewer& viewer,
                      double eye_velocity_deg_s, const RetinaOptions& options, const cv::Mat& previous,
                      const cv::Mat& previous_rate) {
  constexpr const char* kWhere = "retinal_image";
  if (frames.empty()) reject(kWhere, "frames", "must hold at least one frame");
  for (const cv::Mat& frame : frames) {
    if (frame.size() != frames[0].size() || frame.type() != frames[0].type()) {
      reject(kWhere, "frames", "must all have one size and type");
    }
    require_levels(kWhere, "frames", frame);
  }
  require_positive(kWhere, "viewer.pixels_per_degree", viewer.pixels_per_degree);
  require_finite(kWhere, "eye_velocity_deg_s", eye_velocity_deg_s);
  require_finite(kWhere, "options.origin_s", options.origin_s);
  require_substeps(kWhere, options.substeps);
  if (!previous.empty()) {
    if (previous.size() != frames[0].size() || previous.type() != frames[0].type()) {
      reject(kWhere, "previous", "must have the frames' size and type");
    }
    require_levels(kWhere, "previous", previous);
  }
  if (!previous_rate.empty()) {
    if (previous.empty() || previous_rate.size() != frames[0].size() || previous_rate.type() != frames[0].type()) {
      reject(kWhere, "previous_rate", "must come with `previous` and have the frames' size and type");
    }
    if (!cv::checkRange(previous_rate)) reject(kWhere, "previous_rate", "must be finite");
  }
  const int height = frames[0].rows;
  const Line line{frames[0].cols, frames[0].channels()};
  cv::Mat out = cv::Mat::zeros(frames[0].size(), frames[0].type());
  const double velocity_px_s = eye_velocity_deg_s * viewer.pixels_per_degree;
  // Rows are independent (the eye moves along x), so they split across threads with bit-identical results.
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<const double*> rows(frames.size());
    for (int y = range.start; y < range.end; ++y) {
      for (std::size_t f = 0; f < frames.size(); ++f) rows[f] = frames[f].ptr<double>(y);
      line_pass(rows, line, previous.empty() ? nullptr : previous.ptr<double>(y),
                previous_rate.empty() ? nullptr : previous_rate.ptr<double>(y), light,
                FrameMotion(velocity_px_s, options.origin_s), light.row_delay_s(y, height), options.substeps,
                Steps::Lit, {out.ptr<double>(y)});
    }
  });
  return out;
}

cv::Mat ideal_retinal_row(const cv::Mat& profile, const Viewer& viewer, const Gaze& gaze, double t_begin_s,
                          double t_end_s, double origin_s) {
  constexpr const char* kWhere = "ideal_retinal_row";
  check_ideal(kWhere, profile, viewer, gaze.target_velocity_deg_s, gaze.eye_velocity_deg_s, "gaze.eye_velocity_deg_s");
  if (profile.rows != 1) reject(kWhere, "profile", "must be one row");
  require_finite(kWhere, "t_begin_s", t_begin_s);
  require_finite(kWhere, "origin_s", origin_s);
  if (!(std::isfinite(t_end_s) && t_end_s > t_begin_s)) {
    reject(kWhere, "t_end_s", "must be finite and > t_begin_s, got " + number_text(t_end_s));
  }
  const cv::Mat source = profile.clone();
  cv::Mat out(1, source.cols, source.type());
  // x_r samples the object at x_r + x_eye − x_object = x_r + α (t − t_origin).
  const double alpha = (gaze.eye_velocity_deg_s - gaze.target_velocity_deg_s) * viewer.pixels_per_degree;
  mean_over_shifts(source.ptr<double>(0), Line{source.cols, source.channels()}, alpha * (t_begin_s - origin_s),
                   alpha * (t_end_s - origin_s), out.ptr<double>(0));
  return out;
}

cv::Mat ideal_retinal_image(const cv::Mat& image, const Viewer& viewer, const Gaze& gaze, double t_begin_s,
                            double t_end_s, double origin_s) {
  require_levels("ideal_retinal_image", "image", image);
  cv::Mat out(image.size(), image.type());
  for (int y = 0; y < image.rows; ++y) {
    ideal_retinal_row(image.row(y), viewer, gaze, t_begin_s, t_end_s, origin_s).copyTo(out.row(y));
  }
  return out;
}

cv::Mat ideal_xt(const cv::Mat& profile, const Viewer& viewer, double target_velocity_deg_s,
                 double frame_velocity_deg_s, int rows, double row_period_s, double origin_s) {
  constexpr const char* kWhere = "ideal_xt";
  check_ideal(kWhere, profile, viewer, target_velocity_deg_s, frame_velocity_deg_s, "frame_velocity_deg_s");
  if (profile.rows != 1) reject(kWhere, "profile", "must be one row");
  if (rows < 1) reject(kWhere, "rows", "must be >= 1, got " + std::to_string(rows));
  require_positive(kWhere, "row_period_s", row_period_s);
  require_finite(kWhere, "origin_s", origin_s);
  const cv::Mat source = profile.clone();
  cv::Mat out(rows, source.cols, source.type());
  const double alpha = (frame_velocity_deg_s - target_velocity_deg_s) * viewer.pixels_per_degree;
  for (int m = 0; m < rows; ++m) {
    mean_over_shifts(source.ptr<double>(0), Line{source.cols, source.channels()},
                     alpha * (m * row_period_s - origin_s), alpha * ((m + 1) * row_period_s - origin_s),
                     out.ptr<double>(m));
  }
  return out;
}

double edge_width_px(const cv::Mat& row, double low, double high) {
  constexpr const char* kWhere = "edge_width_px";
  if (row.rows != 1 || row.cols < 2 || row.type() != CV_64FC1) reject(kWhere, "row", "must be 1xN CV_64FC1, N >= 2");
  if (!(low >= 0.0 && low < high)) reject(kWhere, "low", "must be in [0, high), got " + number_text(low));
  if (!(high <= 1.0)) reject(kWhere, "high", "must be in (low, 1], got " + number_text(high));
  const double* r = row.ptr<double>(0);
  double lo = r[0], hi = r[0];
  for (int i = 0; i < row.cols; ++i) {
    require_finite(kWhere, "row", r[i]);
    lo = std::min(lo, r[i]);
    hi = std::max(hi, r[i]);
  }
  if (!(hi > lo)) reject(kWhere, "row", "has no edge (constant)");
  const auto crossing = [&](double fraction) {
    const double level = lo + fraction * (hi - lo);
    for (int i = 0; i + 1 < row.cols; ++i) {
      const double a = r[i] - level, b = r[i + 1] - level;
      if (a == 0.0) return static_cast<double>(i);
      if ((a < 0.0) != (b < 0.0) || b == 0.0) return i + a / (a - b);
    }
    return static_cast<double>(row.cols - 1);
  };
  return std::abs(crossing(high) - crossing(low));
}

double pixels_to_arcmin(double pixels, const Viewer& viewer) {
  require_positive("pixels_to_arcmin", "viewer.pixels_per_degree", viewer.pixels_per_degree);
  return pixels / viewer.pixels_per_degree * 60.0;
}

}  // namespace trm
