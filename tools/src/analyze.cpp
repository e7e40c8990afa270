#include "analyze.hpp"
#include "elapsed.hpp"

#include "trm/display_method.hpp"
#include "trm/panel_light.hpp"
#include "trm/plot.hpp"
#include "trm/pursuit.hpp"
#include "trm/resample.hpp"
#include "trm/retina.hpp"
#include "trm/transfer.hpp"
#include "trm/visual_difference.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

constexpr double kSquareSideDeg = 1.0;  // supplement §1.1: "a square of 1 visual degree"

std::vector<double> descending_grid(double from, double to, double step) {
  std::vector<double> grid;
  for (double r = from; r >= to - 1e-9; r -= step) grid.push_back(std::round(r * 1000.0) / 1000.0);
  return grid;
}

std::string text_of(double v, int digits = 4) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}

std::string fixed_text(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

double pixels_saved_percent(double r) { return 100.0 * (0.5 - 0.5 * r * r); }

// The frames of one run, already cut to what the analysis looks at: a band of rows around the analysed line (the
// whole band the encoder's Gaussian reaches from that line), motion along x.
struct Stimulus {
  std::vector<cv::Mat> frames;  // CV_64FC3 linear
  int line = 0;                 // the analysed row within the band
  double velocity_deg_s = 0.0;  // of the pursued target along x
  bool vertical = false;        // the source moved vertically and was transposed
};

// Rows the encoder's Gaussian reaches from a line, for the widest sigma of the grid, plus a pixel for the bilinear U.
int gaussian_reach(const AnalyzeOptions& options, const std::vector<double>& reductions) {
  double widest = 0.0;
  for (double r : reductions) {
    EncoderConfig config = options.pipeline.encoder;
    config.reduction = r;
    widest = std::max(widest, config.effective_sigma());
  }
  return gaussian_radius(widest) + 2;
}

// The supplement's stimulus: a 1-degree square at `contrast`, moving at `speed_deg_s`, on a view just wide enough for
// its travel over the run plus the Gaussian's reach and half a degree either side (the x-t DFT wraps around).
Stimulus square_stimulus(const AnalyzeOptions& options, double ppd, double speed_deg_s, double contrast,
                         double refresh_hz, int reach) {
  const double side = kSquareSideDeg * ppd;
  const double travel = std::abs(speed_deg_s) * ppd * static_cast<double>(options.frames()) / refresh_hz;
  const double margin = reach + 0.5 * side;
  SceneParams params;
  params.width = static_cast<int>(std::ceil(side + travel + 2.0 * margin));
  params.height = static_cast<int>(std::ceil(side + 2.0 * reach));
  params.refresh_hz = refresh_hz;
  MovingSquare square;
  square.side_px = side;
  square.speed_px_s = speed_deg_s * ppd;
  square.contrast = contrast;
  square.start_left_px = speed_deg_s >= 0.0 ? margin : params.width - margin - side;
  const std::unique_ptr<FrameSource> source = make_moving_square(params, square);
  Stimulus s;
  s.line = params.height / 2;
  s.velocity_deg_s = speed_deg_s;
  for (std::int64_t t = 0; t < options.frames(); ++t) s.frames.push_back(source->linear_frame(t));
  return s;
}

// A built-in scene as Experiment 1 shows it: the pursued target is the scene's global motion, else its fastest
// object (as trm compare chooses it); a vertical motion (text scrolls) is analysed along a column, the frames
// transposed so that it runs along x. Only the band of lines the Gaussian reaches from the analysed line is kept.
Stimulus scene_stimulus(const AnalyzeOptions& options, const std::string& scene, double refresh_hz, double ppd,
                        int reach) {
  SceneParams params;
  params.width = options.pipeline.width;
  params.height = options.pipeline.height;
  params.refresh_hz = refresh_hz;
  params.seed = options.pipeline.seed;
  // 2 x 2 samples per pixel instead of 4 x 4: the scenes' edges stay anti-aliased to a quarter pixel, and the
  // textured scenes' construction at the monitor's size, most of Experiment 1's time, takes a quarter as long.
  params.supersample = 2;
  const std::unique_ptr<FrameSource> source = make_scene(scene, params);
  const Motion motion = source->motion(0);
  Stimulus s;
  double velocity_px_s = 0.0;
  int line = source->height() / 2;
  if (motion.global_velocity_px_s[0] != 0.0 || motion.global_velocity_px_s[1] != 0.0) {
    s.vertical = std::abs(motion.global_velocity_px_s[1]) > std::abs(motion.global_velocity_px_s[0]);
    velocity_px_s = s.vertical ? motion.global_velocity_px_s[1] : motion.global_velocity_px_s[0];
    line = s.vertical ? source->width() / 2 : source->height() / 2;
  } else {
    for (const MotionObject& object : motion.objects) {
      if (std::abs(object.velocity_px_s[0]) > std::abs(velocity_px_s)) {
        velocity_px_s = object.velocity_px_s[0];
        line = std::clamp(static_cast<int>(object.bounds.y + 0.5 * object.bounds.height), 0, source->height() - 1);
      }
    }
  }
  s.velocity_deg_s = velocity_px_s / ppd;
  const int lines = s.vertical ? source->width() : source->height();
  const int first = std::max(0, line - reach);
  const int last = std::min(lines - 1, line + reach);
  s.line = line - first;
  for (std::int64_t t = 0; t < options.frames(); ++t) {
    cv::Mat frame = source->linear_frame(t);
    if (s.vertical) frame = frame.t();
    s.frames.push_back(frame.rowRange(first, last + 1).clone());
  }
  return s;
}

// The analysed line's x-t levels (one row per frame) `method` drives for the stimulus, through the method's real
// GPU side and headset side (trm: TrmEncoder and the double-precision ReferenceDecoder).
cv::Mat driven_levels(const Stimulus& stimulus, const PipelineOptions& base, const std::string& method,
                      double reduction) {
  PipelineOptions run = base;
  run.method = method;
  run.impl = "reference";
  run.impl_given = false;
  run.encoder.reduction = reduction;
  run.encoder.stereo = false;
  const MethodChoice choice = find_display_method(method);
  const MethodSetup setup = run.method_setup();
  const std::unique_ptr<MethodSender> sender = choice.method->make_sender(setup);
  const std::unique_ptr<MethodDisplay> display = choice.method->make_display(setup);
  std::vector<cv::Mat> rows;
  for (std::size_t i = 0; i < stimulus.frames.size(); ++i) {
    const auto t = static_cast<std::int64_t>(i);
    const cv::Mat& frame = stimulus.frames[i];
    DecodedFrame shown;
    if (sender->sends(t, 0)) {
      const Transmission sent = sender->send(frame, t, 0);
      shown = display->show(sent.frame, {});
    } else {
      shown = display->show_unsent(unsent_slot(t, 0, frame.size(), run.encoder));
    }
    rows.push_back(luma(steady_levels(run.panel, run.output_bits, shown.drive_codes.row(stimulus.line))));
  }
  cv::Mat levels;
  cv::vconcat(rows, levels);
  return levels;
}

// The §1.4 cycle of one full frame and k reduced frames, for the analysis only (the encoder and decoders do 1 + 1).
// It follows DESIGN §4 with the full frame boosting the high frequencies k times, as the supplement says it must:
//   beta = (k + 1) I_t - k L_t,  shown = clamp(beta),  rho = beta - shown,
//   each of the k reduced frames t + j:  alpha' = clamp(lin(U(i_{t+j})) + w rho / k),  w = exp(-s c)
// (c the luma motion test against L_t), so that a still scene averages exactly I over the cycle. The reduced frames are
// the encoder's own (reduce_codes), the drive is the panel's held inverse quantised to the output bits. At k = 1 it is
// the reference decoder's rule for an OLED; run_analyze reports both energies there to show how far they agree.
cv::Mat cycle_levels(const Stimulus& stimulus, const PipelineOptions& base, double reduction, int k,
                     double& clipped_light, double& full_light) {
  EncoderConfig config = base.encoder;
  config.reduction = reduction;
  const Panel& panel = base.panel;
  const double top = std::ldexp(1.0, base.output_bits) - 1.0;
  const auto low_pass = [&](const cv::Mat& full_codes) {
    const cv::Mat reduced = dequantise(reduce_codes(full_codes, config), config.bits);
    if (config.resample_space == ResampleSpace::Encoded) {
      return to_linear(upsample(reduced, full_codes.cols, full_codes.rows), config.transfer);
    }
    return upsample(to_linear(reduced, config.transfer), full_codes.cols, full_codes.rows);
  };
  cv::Mat full_low, residual;
  std::vector<cv::Mat> rows;
  for (std::size_t i = 0; i < stimulus.frames.size(); ++i) {
    const cv::Mat codes = quantise(to_encoded(stimulus.frames[i], config.transfer), config.bits);
    const cv::Mat low = low_pass(codes);
    cv::Mat wanted;
    if (i % static_cast<std::size_t>(k + 1) == 0) {
      const cv::Mat image = to_linear(dequantise(codes, config.bits), config.transfer);
      const cv::Mat beta = (k + 1.0) * image - k * low;
      wanted = cv::min(cv::max(beta, 0.0), 1.0);
      residual = beta - wanted;
      // The boost the full frame could not show (the supplement's second objection to long cycles): with motion the
      // reduced frames take little of it back (w -> 0), so it is counted here, where it arises.
      const cv::Mat lost = cv::abs(residual);
      clipped_light += cv::sum(lost)[0] + cv::sum(lost)[1] + cv::sum(lost)[2];
      full_low = low;
      full_light += cv::sum(image)[0] + cv::sum(image)[1] + cv::sum(image)[2];
    } else {
      const cv::Mat y_full = luma(full_low), y_low = luma(low);
      cv::Mat with_residual = low.clone();
      for (int y = 0; y < low.rows; ++y) {
        for (int x = 0; x < low.cols; ++x) {
          const double a = y_full.at<double>(y, x), b = y_low.at<double>(y, x);
          const double c = a + b > 0.0 ? std::abs(a - b) / (a + b) : 0.0;
          const double w = c == 0.0 ? 1.0 : std::exp(-base.sensitivity * c);
          with_residual.at<cv::Vec3d>(y, x) += w * residual.at<cv::Vec3d>(y, x) / static_cast<double>(k);
        }
      }
      wanted = cv::min(cv::max(with_residual, 0.0), 1.0);
    }
    cv::Mat drive_codes(wanted.size(), CV_16UC3);
    for (int y = 0; y < wanted.rows; ++y) {
      for (int x = 0; x < wanted.cols; ++x) {
        for (int c = 0; c < 3; ++c) {
          const double v = panel.drive_from_linear(wanted.at<cv::Vec3d>(y, x)[c], c);
          drive_codes.at<cv::Vec3w>(y, x)[c] = static_cast<std::uint16_t>(std::floor(v * top + 0.5));
        }
      }
    }
    rows.push_back(luma(steady_levels(panel, base.output_bits, drive_codes.row(stimulus.line))));
  }
  cv::Mat levels;
  cv::vconcat(rows, levels);
  return levels;
}

// Everything the energy of a run needs besides its levels: the panel's light, the eye and the full-rate reference.
class EnergyMeter {
 public:
  EnergyMeter(const AnalyzeOptions& options, const Stimulus& stimulus, double ppd, double refresh_hz)
      : options_(options),
        stimulus_(stimulus),
        light_(light_of(options, refresh_hz)),
        viewer_(custom_viewer(ppd)),
        gaze_(Gaze::pursuit(stimulus.velocity_deg_s)) {
    retina_.substeps = options.retina_substeps();
    retina_.row = stimulus.line;
    retina_.rows = stimulus.frames.front().rows;
    rate_ = xt_samples_per_second(light_, retina_.substeps);
    lag_ = retinal_velocity_deg_s(stimulus.velocity_deg_s);
    full_rate_ = seen(driven_levels(stimulus, options.pipeline, "full", 1.0));
  }
  double energy_of(const cv::Mat& levels) const {
    return visual_difference_energy(seen(levels), full_rate_, viewer_.pixels_per_degree, rate_, lag_);
  }
  double trm_energy(double reduction) const {
    return energy_of(driven_levels(stimulus_, options_.pipeline, "trm", reduction));
  }

 private:
  static PanelLight light_of(const AnalyzeOptions& options, double refresh_hz) {
    Panel panel = options.pipeline.panel;
    panel.oled.duty = options.persistence;
    return panel_light(panel, refresh_hz);
  }
  cv::Mat seen(const cv::Mat& levels) const { return target_frame_xt(levels, light_, viewer_, gaze_, retina_); }

  const AnalyzeOptions& options_;
  const Stimulus& stimulus_;
  PanelLight light_;
  Viewer viewer_;
  Gaze gaze_;
  RetinaOptions retina_;
  double rate_ = 0.0, lag_ = 0.0;
  cv::Mat full_rate_;
};

void require_list(const std::vector<double>& values, const std::string& option, const std::string& rule,
                  const std::function<bool(double)>& valid) {
  if (values.empty()) throw std::invalid_argument(option + " needs at least one value");
  for (double v : values) {
    if (!valid(v)) throw std::invalid_argument(option + " values must be " + rule + ", got " + text_of(v, 10));
  }
}

bool positive_finite(double v) { return std::isfinite(v) && v > 0.0; }

bool valid_refresh(double hz) {
  try {
    validate_refresh_hz(hz, "refresh");
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

// Smallest r of the descending grid whose energy, and that of every larger r, stays under `threshold`; refined by
// bisection between it and the next grid point (energy is not monotone in r at the resolution of single pixels, so the
// grid decides the bracket and the bisection only sharpens it).
void find_threshold(Exp1Point& point, const EnergyMeter& meter, const std::vector<double>& grid, double threshold,
                    int bisections, const std::function<void()>& step) {
  std::map<double, double, std::greater<>> measured;
  const auto energy = [&](double r) {
    const auto found = measured.find(r);
    if (found != measured.end()) return found->second;
    const double e = meter.trm_energy(r);
    step();
    measured[r] = e;
    return e;
  };
  std::size_t passing = grid.size();  // index of the smallest passing grid r
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (energy(grid[i]) > threshold) break;
    passing = i;
  }
  if (passing == grid.size()) {
    point.threshold_reduction = grid.front();  // even the largest r is over the threshold
  } else if (passing + 1 == grid.size()) {
    point.threshold_reduction = grid.back();
    point.below_grid = true;
  } else {
    double pass = grid[passing], fail = grid[passing + 1];
    for (int b = 0; b < bisections; ++b) {
      const double mid = std::round(0.5 * (pass + fail) * 1e4) / 1e4;
      (energy(mid) <= threshold ? pass : fail) = mid;
    }
    point.threshold_reduction = pass;
  }
  for (const auto& [r, e] : measured) {
    point.reductions.push_back(r);
    point.energies.push_back(e);
  }
}

// The energies of the study at `parameter`'s values, one curve per (value, speed), r descending.
std::vector<std::vector<const StudyPoint*>> curves_of(const AnalyzeResult& result, const std::string& parameter,
                                                     double speed) {
  std::map<double, std::vector<const StudyPoint*>> by_value;
  for (const StudyPoint& p : result.study) {
    if (p.parameter == parameter && p.speed_deg_s == speed) by_value[p.value].push_back(&p);
  }
  std::vector<std::vector<const StudyPoint*>> curves;
  for (auto& [value, points] : by_value) curves.push_back(points);
  return curves;
}

// Mean slope (energy per % saved) of a curve over the points with pixels saved in (lo, hi].
double mean_slope(const std::vector<const StudyPoint*>& curve, double lo, double hi) {
  std::vector<const StudyPoint*> sorted = curve;
  std::sort(sorted.begin(), sorted.end(),
            [](const StudyPoint* a, const StudyPoint* b) { return a->pixels_saved_percent < b->pixels_saved_percent; });
  double first_x = NAN, first_y = NAN, last_x = NAN, last_y = NAN;
  for (const StudyPoint* p : sorted) {
    if (p->pixels_saved_percent < lo - 1e-9 || p->pixels_saved_percent > hi + 1e-9) continue;
    if (std::isnan(first_x)) {
      first_x = p->pixels_saved_percent;
      first_y = p->energy;
    }
    last_x = p->pixels_saved_percent;
    last_y = p->energy;
  }
  return last_x > first_x ? (last_y - first_y) / (last_x - first_x) : NAN;
}

// The study's energy at (parameter, value, speed) at the grid r nearest `r`.
double energy_at(const AnalyzeResult& result, const std::string& parameter, double value, double speed, double r) {
  double best = std::numeric_limits<double>::infinity(), energy = NAN;
  for (const StudyPoint& p : result.study) {
    if (p.parameter == parameter && p.value == value && p.speed_deg_s == speed && std::abs(p.reduction - r) < best) {
      best = std::abs(p.reduction - r);
      energy = p.energy;
    }
  }
  return energy;
}

std::vector<TrendCheck> check_trends(const AnalyzeResult& result) {
  const AnalyzeOptions& o = result.options;
  std::vector<TrendCheck> checks;
  // Steepening: the slope over (40, 48] % saved (r from 0.45 down to 0.2) against the slope over [0, 40] %, every
  // curve of every figure. r = 0.1 (49.5 %) is left out of the slope and reported on its own: there the energy of
  // several curves falls again (docs/analyze.md).
  {
    TrendCheck c{"energy rises steeply past about 40 % pixels saved (up to r = 0.2)", true, ""};
    double least = std::numeric_limits<double>::infinity(), most = 0.0;
    int curves = 0;
    for (const char* parameter : {"contrast", "ppd", "refresh"}) {
      for (double speed : o.speeds) {
        for (const auto& curve : curves_of(result, parameter, speed)) {
          const double low = mean_slope(curve, 0.0, 40.0), high = mean_slope(curve, 40.0, 48.0);
          if (!(std::isfinite(low) && std::isfinite(high))) continue;
          const double ratio = low > 0.0 ? high / low : std::numeric_limits<double>::infinity();
          ++curves;
          least = std::min(least, ratio);
          most = std::max(most, ratio);
          if (!(ratio > 1.0)) c.holds = false;
        }
      }
    }
    if (curves == 0) c.holds = false;
    int falling = 0;
    for (const char* parameter : {"contrast", "ppd", "refresh"}) {
      for (double speed : o.speeds) {
        for (const auto& curve : curves_of(result, parameter, speed)) {
          if (curve.size() >= 2 && curve.back()->reduction <= 0.1 + 1e-9 &&
              curve.back()->energy < curve[curve.size() - 2]->energy) {
            ++falling;
          }
        }
      }
    }
    c.evidence = "slope over 40-48 % saved / slope over 0-40 %: " + text_of(least, 3) + " to " + text_of(most, 3) +
                 " over " + std::to_string(curves) + " curves; at r = 0.1 the energy falls below r = 0.2's on " +
                 std::to_string(falling) + " curves";
    checks.push_back(c);
  }
  // Monotone in each parameter at every speed and every r < 1 of the grid.
  const auto monotone = [&](const std::string& parameter, const std::vector<double>& values, bool increasing,
                            const std::string& claim) {
    TrendCheck c{claim, true, ""};
    int tested = 0, held = 0;
    for (double speed : o.speeds) {
      for (double r : o.reductions) {
        if (r >= 1.0) continue;
        std::vector<double> sorted = values;
        std::sort(sorted.begin(), sorted.end());
        bool ok = true;
        for (std::size_t i = 1; i < sorted.size(); ++i) {
          const double a = energy_at(result, parameter, sorted[i - 1], speed, r);
          const double b = energy_at(result, parameter, sorted[i], speed, r);
          if (increasing ? !(b >= a) : !(b <= a)) ok = false;
        }
        ++tested;
        held += ok ? 1 : 0;
      }
    }
    c.holds = tested > 0 && held == tested;
    c.evidence = "monotone at " + std::to_string(held) + " of " + std::to_string(tested) + " (speed, r) points";
    checks.push_back(c);
  };
  monotone("contrast", o.contrasts, true, "energy falls with lower contrast");
  monotone("ppd", o.ppds, false, "energy falls with higher pixels per degree");
  monotone("refresh", o.refreshes, false, "energy falls with higher refresh rate");
  // Spread of each parameter over its range at r = 0.5 (TRM 1/2), the mean over speeds of log(max / min).
  {
    std::map<std::string, double> spread;
    for (const auto& [parameter, values] : std::vector<std::pair<std::string, std::vector<double>>>{
             {"contrast", o.contrasts}, {"ppd", o.ppds}, {"refresh", o.refreshes}}) {
      double sum = 0.0;
      for (double speed : o.speeds) {
        double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
        for (double v : values) {
          const double e = energy_at(result, parameter, v, speed, 0.5);
          lo = std::min(lo, e);
          hi = std::max(hi, e);
        }
        sum += lo > 0.0 ? std::log(hi / lo) : 0.0;
      }
      spread[parameter] = std::exp(sum / static_cast<double>(o.speeds.size()));
    }
    TrendCheck c{"refresh rate matters less than contrast and ppd", spread["refresh"] < spread["contrast"] &&
                                                                         spread["refresh"] < spread["ppd"], ""};
    c.evidence = "max/min energy over each range at r = 0.5: contrast " + text_of(spread["contrast"], 3) + ", ppd " +
                 text_of(spread["ppd"], 3) + ", refresh " + text_of(spread["refresh"], 3);
    checks.push_back(c);
  }
  // Experiment 1: the threshold r does not rise with refresh rate, scene by scene.
  {
    // Thresholds closer than the bisection's resolution (the widest grid gap / 2^4) are ties.
    double widest_gap = 0.0;
    for (std::size_t i = 1; i < o.reductions.size(); ++i) {
      widest_gap = std::max(widest_gap, o.reductions[i - 1] - o.reductions[i]);
    }
    const double resolution = widest_gap / 16.0;
    TrendCheck c{"Experiment 1: threshold r falls (does not rise) with refresh rate", true, ""};
    std::map<std::string, std::vector<const Exp1Point*>> by_scene;
    for (const Exp1Point& p : result.exp1) by_scene[p.scene].push_back(&p);
    std::string detail;
    for (auto& [scene, points] : by_scene) {
      std::sort(points.begin(), points.end(),
                [](const Exp1Point* a, const Exp1Point* b) { return a->refresh_hz < b->refresh_hz; });
      bool ok = true;
      for (std::size_t i = 1; i < points.size(); ++i) {
        if (points[i]->threshold_reduction > points[i - 1]->threshold_reduction + resolution + 1e-9) ok = false;
      }
      c.holds = c.holds && ok;
      detail += (detail.empty() ? "" : "; ") + scene + " " + fixed_text(points.front()->threshold_reduction, 3) + " -> " +
                fixed_text(points.back()->threshold_reduction, 3) + (ok ? "" : " (not monotone)");
    }
    c.evidence = detail + " (ties within " + text_of(resolution, 3) + ")";
    checks.push_back(c);
  }
  {
    TrendCheck c{"Experiment 1: r of 0.4 is indistinguishable everywhere (every threshold r <= 0.4)", true, ""};
    double worst = 0.0;
    for (const Exp1Point& p : result.exp1) worst = std::max(worst, p.threshold_reduction);
    c.holds = !result.exp1.empty() && worst <= o.calibration_reduction + 1e-9;
    c.evidence = "largest threshold r " + fixed_text(worst, 3);
    checks.push_back(c);
  }
  if (!result.cycles.empty()) {
    // §1.4: at (about) equal pixels saved, 1 + 1 has the least energy; and more reduced frames lower the cycle rate.
    TrendCheck c{"1 full + 1 reduced frame is the best cycle (least energy at equal pixels saved)", true, ""};
    int compared = 0, won = 0;
    for (double speed : o.speeds) {
      for (const CyclePoint& longer : result.cycles) {
        if (longer.reduced_frames == 1 || longer.speed_deg_s != speed) continue;
        // The 1 + 1 energy at the same saving, interpolated over its curve (saving rises as r falls).
        std::vector<const CyclePoint*> pair;
        for (const CyclePoint& p : result.cycles) {
          if (p.reduced_frames == 1 && p.speed_deg_s == speed) pair.push_back(&p);
        }
        std::sort(pair.begin(), pair.end(), [](const CyclePoint* a, const CyclePoint* b) {
          return a->pixels_saved_percent < b->pixels_saved_percent;
        });
        for (std::size_t i = 1; i < pair.size(); ++i) {
          const double x0 = pair[i - 1]->pixels_saved_percent, x1 = pair[i]->pixels_saved_percent;
          if (longer.pixels_saved_percent < x0 || longer.pixels_saved_percent > x1 || x1 <= x0) continue;
          const double f = (longer.pixels_saved_percent - x0) / (x1 - x0);
          const double e_pair = pair[i - 1]->energy + f * (pair[i]->energy - pair[i - 1]->energy);
          ++compared;
          won += e_pair <= longer.energy ? 1 : 0;
          break;
        }
      }
    }
    c.holds = compared > 0 && won == compared;
    c.evidence = "1 + 1 below the longer cycle at " + std::to_string(won) + " of " + std::to_string(compared) +
                 " points of equal saving (1 + 1 saves at most 50 %; points beyond it are not compared)";
    checks.push_back(c);
  }
  return checks;
}

}  // namespace

void AnalyzeOptions::apply_defaults() {
  if (speeds.empty()) speeds = quick ? std::vector<double>{10.0} : std::vector<double>{5.0, 20.0};
  if (contrasts.empty()) contrasts = quick ? std::vector<double>{0.1, 0.4} : std::vector<double>{0.05, 0.1, 0.2, 0.4};
  if (ppds.empty()) ppds = quick ? std::vector<double>{15.0, 45.0} : std::vector<double>{15.0, 30.0, 45.0, 60.0};
  if (refreshes.empty()) refreshes = quick ? std::vector<double>{90.0, 165.0} : std::vector<double>{90.0, 120.0, 144.0, 165.0};
  if (reductions.empty()) reductions = quick ? std::vector<double>{1.0, 0.7, 0.5, 0.3, 0.1} : descending_grid(1.0, 0.1, 0.1);
  if (scenes.empty()) scenes = quick ? std::vector<std::string>{"discs"} : std::vector<std::string>{"discs", "text", "panorama"};
  if (exp1_refreshes.empty()) {
    exp1_refreshes = quick ? std::vector<double>{100.0, 165.0} : std::vector<double>{100.0, 120.0, 144.0, 165.0};
  }
  if (cycles.empty()) cycles = quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 3};
  std::sort(reductions.begin(), reductions.end(), std::greater<>());
}

std::int64_t AnalyzeOptions::frames() const { return pipeline.frames > 0 ? pipeline.frames : pipeline.default_frames; }
int AnalyzeOptions::retina_substeps() const { return substeps > 0 ? substeps : kDefaultRetinaSubsteps; }

void AnalyzeOptions::validate() const {
  pipeline.validate();
  if (!positive_finite(ppd)) throw std::invalid_argument("--ppd must be a finite number of pixels per degree > 0, got " + text_of(ppd, 10));
  if (!(contrast >= 0.0 && contrast <= 1.0)) throw std::invalid_argument("--contrast must be a Michelson contrast in [0, 1], got " + text_of(contrast, 10));
  if (!(persistence > 0.0 && persistence <= 1.0)) throw std::invalid_argument("--persistence must be in (0, 1], got " + text_of(persistence, 10));
  require_list(speeds, "--speeds", "finite deg/s", [](double v) { return std::isfinite(v); });
  require_list(contrasts, "--contrasts", "Michelson contrasts in [0, 1]", [](double v) { return v >= 0.0 && v <= 1.0; });
  require_list(ppds, "--ppds", "finite pixels per degree > 0", positive_finite);
  require_list(refreshes, "--refreshes", "refresh rates in [1, 1000] Hz", valid_refresh);
  require_list(reductions, "--reductions", "in (0, 1]", [](double r) { return r > 0.0 && r <= 1.0; });
  require_list(exp1_refreshes, "--exp1-refreshes", "refresh rates in [1, 1000] Hz", valid_refresh);
  if (!positive_finite(exp1_ppd)) throw std::invalid_argument("--exp1-ppd must be a finite number of pixels per degree > 0, got " + text_of(exp1_ppd, 10));
  for (double r : reductions) {
    EncoderConfig config = pipeline.encoder;
    config.reduction = r;
    config.validate();
  }
  if (scenes.empty()) throw std::invalid_argument("--scenes needs at least one scene");
  std::set<std::string> seen;
  for (const std::string& scene : scenes) {
    bool known = false;
    for (const std::string& name : scene_names()) known = known || name == scene;
    if (!known) {
      std::string list;
      for (const std::string& name : scene_names()) list += (list.empty() ? "" : ", ") + name;
      throw std::invalid_argument("--scenes: unknown scene '" + scene + "' (available: " + list + ")");
    }
    if (!seen.insert(scene).second) throw std::invalid_argument("--scenes: '" + scene + "' is named twice");
  }
  if (!(calibration_reduction > 0.0 && calibration_reduction <= 1.0)) {
    throw std::invalid_argument("--calibrate-r must be in (0, 1], got " + text_of(calibration_reduction, 10));
  }
  if (!valid_refresh(calibration_refresh_hz)) {
    throw std::invalid_argument("--calibrate-refresh must be a refresh rate in [1, 1000] Hz, got " + text_of(calibration_refresh_hz, 10));
  }
  bool known = false;
  for (const std::string& name : scene_names()) known = known || name == calibration_scene;
  if (!known) throw std::invalid_argument("--calibrate-scene: unknown scene '" + calibration_scene + "'");
  if (cycles.empty()) throw std::invalid_argument("--cycles needs at least one k");
  for (int k : cycles) {
    if (k < 1 || k > 8) throw std::invalid_argument("--cycles: k reduced frames per full frame must be in [1, 8], got " + std::to_string(k));
  }
  if (substeps < 0) throw std::invalid_argument("--substeps must be >= 1 (leave it out for the default)");
  if (frames() < 2) throw std::invalid_argument("--frames must be at least 2 (a full and a reduced frame)");
}

std::int64_t analyze_work(const AnalyzeOptions& o) {
  const auto grid = static_cast<std::int64_t>(o.reductions.size());
  const auto speeds = static_cast<std::int64_t>(o.speeds.size());
  const auto values = static_cast<std::int64_t>(o.contrasts.size() + o.ppds.size() + o.refreshes.size());
  const std::int64_t study = values * speeds * (grid + 1);
  // Experiment 1: the calibration point, then per scene and rate the reference, the grid (at most) and 4 bisections.
  const std::int64_t exp1 = 2 + static_cast<std::int64_t>(o.scenes.size() * o.exp1_refreshes.size()) * (grid + 5);
  const std::int64_t cycles = speeds * (1 + grid * static_cast<std::int64_t>(o.cycles.size()) + grid);
  return (study + exp1 + cycles) * o.frames();
}

AnalyzeResult run_analyze(const AnalyzeOptions& options,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress) {
  options.validate();
  const auto start = std::chrono::steady_clock::now();
  AnalyzeResult result;
  result.options = options;
  const std::int64_t total = analyze_work(options);
  std::int64_t done = 0;
  const auto step = [&] {
    done = std::min(total, done + options.frames());
    if (progress) progress(done, total);
  };
  const int reach = gaussian_reach(options, options.reductions);

  // Figs. 2-4: one parameter varied at a time, the others at the study's defaults.
  struct Varied {
    const char* parameter;
    const std::vector<double>* values;
  };
  for (const Varied& varied : {Varied{"contrast", &options.contrasts}, Varied{"ppd", &options.ppds},
                               Varied{"refresh", &options.refreshes}}) {
    for (double value : *varied.values) {
      for (double speed : options.speeds) {
        const std::string parameter = varied.parameter;
        const double ppd = parameter == "ppd" ? value : options.ppd;
        const double contrast = parameter == "contrast" ? value : options.contrast;
        const double refresh = parameter == "refresh" ? value : options.pipeline.refresh_hz;
        const Stimulus stimulus = square_stimulus(options, ppd, speed, contrast, refresh, reach);
        const EnergyMeter meter(options, stimulus, ppd, refresh);
        step();
        for (double r : options.reductions) {
          result.study.push_back({parameter, value, speed, r, pixels_saved_percent(r), meter.trm_energy(r)});
          step();
        }
      }
    }
  }

  // Experiment 1: the threshold is calibrated once, on the calibration scene at its rate and r.
  {
    const Stimulus stimulus =
        scene_stimulus(options, options.calibration_scene, options.calibration_refresh_hz, options.exp1_ppd, reach);
    const EnergyMeter meter(options, stimulus, options.exp1_ppd, options.calibration_refresh_hz);
    step();
    result.threshold_energy = meter.trm_energy(options.calibration_reduction);
    step();
  }
  for (const std::string& scene : options.scenes) {
    for (double refresh : options.exp1_refreshes) {
      const Stimulus stimulus = scene_stimulus(options, scene, refresh, options.exp1_ppd, reach);
      const EnergyMeter meter(options, stimulus, options.exp1_ppd, refresh);
      step();
      Exp1Point point;
      point.scene = scene;
      point.refresh_hz = refresh;
      point.target_velocity_deg_s = stimulus.velocity_deg_s;
      point.vertical = stimulus.vertical;
      find_threshold(point, meter, options.reductions, result.threshold_energy, 4, step);
      result.exp1.push_back(std::move(point));
    }
  }

  // §1.4: 1 + k cycles on the study's default square, over whole cycles of every k (the x-t DFT wraps in time, so
  // a cut cycle would add a step of its own), the same frames for every k.
  std::int64_t cycle_length = 2;
  for (int k : options.cycles) cycle_length = std::lcm(cycle_length, static_cast<std::int64_t>(k + 1));
  AnalyzeOptions whole_cycles = options;
  whole_cycles.pipeline.frames = (options.frames() + cycle_length - 1) / cycle_length * cycle_length;
  result.cycle_frames = whole_cycles.pipeline.frames;
  for (double speed : options.speeds) {
    const Stimulus stimulus = square_stimulus(whole_cycles, options.ppd, speed, options.contrast,
                                              options.pipeline.refresh_hz, reach);
    const EnergyMeter meter(options, stimulus, options.ppd, options.pipeline.refresh_hz);
    step();
    for (int k : options.cycles) {
      for (double r : options.reductions) {
        CyclePoint p;
        p.reduced_frames = k;
        p.speed_deg_s = speed;
        p.reduction = r;
        p.pixels_saved_percent = 100.0 * k / (k + 1.0) * (1.0 - r * r);
        p.cycle_hz = options.pipeline.refresh_hz / (k + 1.0);
        double clipped = 0.0, full_light = 0.0;
        p.energy = meter.energy_of(cycle_levels(stimulus, options.pipeline, r, k, clipped, full_light));
        p.clipped_percent = full_light > 0.0 ? 100.0 * clipped / full_light : 0.0;
        step();
        p.pipeline_energy = NAN;
        if (k == 1) {
          p.pipeline_energy = meter.trm_energy(r);
          step();
        }
        result.cycles.push_back(p);
      }
    }
  }
  result.trends = check_trends(result);
  result.seconds = seconds_since(start);
  if (progress) progress(total, total);
  return result;
}

std::string study_csv(const AnalyzeResult& result) {
  std::ostringstream out;
  out.precision(10);
  out << "parameter,value,speed_deg_s,reduction,pixels_saved_percent,energy\n";
  for (const StudyPoint& p : result.study) {
    out << p.parameter << ',' << p.value << ',' << p.speed_deg_s << ',' << p.reduction << ',' << p.pixels_saved_percent
        << ',' << p.energy << '\n';
  }
  return out.str();
}

std::string exp1_csv(const AnalyzeResult& result) {
  std::ostringstream out;
  out.precision(10);
  out << "scene,refresh_hz,ppd,target_velocity_deg_s,axis,threshold_reduction,below_grid,pixels_saved_percent,"
         "threshold_energy,reductions,energies\n";
  for (const Exp1Point& p : result.exp1) {
    std::string rs, es;
    for (std::size_t i = 0; i < p.reductions.size(); ++i) {
      if (i > 0) {
        rs.push_back(';');
        es.push_back(';');
      }
      rs.append(text_of(p.reductions[i], 6));
      es.append(text_of(p.energies[i], 8));
    }
    out << p.scene << ',' << p.refresh_hz << ',' << result.options.exp1_ppd << ',' << p.target_velocity_deg_s << ','
        << (p.vertical ? "y" : "x") << ',' << p.threshold_reduction << ',' << (p.below_grid ? 1 : 0) << ','
        << p.pixels_saved_percent() << ',' << result.threshold_energy << ',' << rs << ',' << es << '\n';
  }
  return out.str();
}

std::string cycles_csv(const AnalyzeResult& result) {
  std::ostringstream out;
  out.precision(10);
  out << "reduced_frames,speed_deg_s,reduction,pixels_saved_percent,cycle_hz,energy,clipped_percent,pipeline_energy\n";
  for (const CyclePoint& p : result.cycles) {
    out << p.reduced_frames << ',' << p.speed_deg_s << ',' << p.reduction << ',' << p.pixels_saved_percent << ','
        << p.cycle_hz << ',' << p.energy << ',' << p.clipped_percent << ','
        << (std::isnan(p.pipeline_energy) ? std::string() : text_of(p.pipeline_energy, 10)) << '\n';
  }
  return out.str();
}

namespace {

std::string settings_line(const AnalyzeResult& result) {
  const AnalyzeOptions& o = result.options;
  return "panel " + o.pipeline.panel.name + " (persistence " + text_of(o.persistence) + "), " +
         std::to_string(o.frames()) + " frames per run, " + std::to_string(o.retina_substeps()) +
         " sub-frame steps, sensitivity " + text_of(o.pipeline.sensitivity) + ", " + std::to_string(o.pipeline.encoder.bits) +
         "-bit link";
}

}  // namespace

std::string analyze_summary(const AnalyzeResult& result) {
  std::ostringstream out;
  out << "  threshold energy " << text_of(result.threshold_energy) << " (" << result.options.calibration_scene << ", "
      << text_of(result.options.calibration_refresh_hz) << " Hz, r = " << text_of(result.options.calibration_reduction)
      << ")\n  Experiment 1 threshold r:";
  std::string scene;
  for (const Exp1Point& p : result.exp1) {
    if (p.scene != scene) out << "\n    " << p.scene << ":";
    scene = p.scene;
    out << " " << text_of(p.refresh_hz) << " Hz " << (p.below_grid ? "<=" : "") << fixed_text(p.threshold_reduction, 3);
  }
  out << "\n";
  for (const TrendCheck& t : result.trends) {
    out << "  [" << (t.holds ? "reproduces" : "does not reproduce") << "] " << t.claim << ": " << t.evidence << "\n";
  }
  return out.str();
}

std::string analyze_markdown(const AnalyzeResult& result) {
  const AnalyzeOptions& o = result.options;
  std::ostringstream out;
  out << "# trm analyze\n\n" << settings_line(result) << "; " << fixed_text(result.seconds, 1) << " s.\n\n";
  out << "## Trends\n\n| claim | measured | evidence |\n|---|---|---|\n";
  for (const TrendCheck& t : result.trends) {
    out << "| " << t.claim << " | " << (t.holds ? "reproduces" : "does not reproduce") << " | " << t.evidence << " |\n";
  }
  out << "\n## Figs. 2-4: energy against pixels saved\n\nDefaults: " << text_of(o.ppd) << " ppd, "
      << text_of(o.pipeline.refresh_hz) << " Hz, contrast " << text_of(o.contrast) << ", a " << kSquareSideDeg
      << "-degree square.\n\n";
  for (const char* parameter : {"contrast", "ppd", "refresh"}) {
    for (double speed : o.speeds) {
      out << "**" << parameter << ", " << text_of(speed) << " deg/s**\n\n| " << parameter << " |";
      for (double r : o.reductions) out << " r " << text_of(r) << " |";
      out << "\n|---|";
      for (std::size_t i = 0; i < o.reductions.size(); ++i) out << "---:|";
      out << "\n";
      for (const auto& curve : curves_of(result, parameter, speed)) {
        out << "| " << text_of(curve.front()->value) << " |";
        for (const StudyPoint* p : curve) out << " " << fixed_text(p->energy, 2) << " |";
        out << "\n";
      }
      out << "\n";
    }
  }
  out << "## Experiment 1 prediction (" << text_of(o.exp1_ppd) << " ppd, view " << o.pipeline.width << "x"
      << o.pipeline.height << ")\n\nThreshold energy " << text_of(result.threshold_energy) << ": the energy of "
      << o.calibration_scene << " at " << text_of(o.calibration_refresh_hz) << " Hz and r = "
      << text_of(o.calibration_reduction) << ".\n\n| scene | target deg/s | ";
  for (double hz : o.exp1_refreshes) out << text_of(hz) << " Hz | ";
  out << "\n|---|---:|";
  for (std::size_t i = 0; i < o.exp1_refreshes.size(); ++i) out << "---:|";
  out << "\n";
  for (const std::string& scene : o.scenes) {
    bool first = true;
    for (const Exp1Point& p : result.exp1) {
      if (p.scene != scene) continue;
      if (first) out << "| " << scene << " | " << fixed_text(std::abs(p.target_velocity_deg_s), 1) << (p.vertical ? " (y)" : "") << " |";
      first = false;
      out << " " << (p.below_grid ? "<= " : "") << fixed_text(p.threshold_reduction, 3) << " (" << fixed_text(p.pixels_saved_percent(), 1)
          << " %) |";
    }
    out << "\n";
  }
  out << "\n## §1.4: 1 full + k reduced frames (" << text_of(o.ppd) << " ppd, " << text_of(o.pipeline.refresh_hz)
      << " Hz, contrast " << text_of(o.contrast) << ", " << result.cycle_frames
      << " frames)\n\n| k | speed | r | pixels saved % | cycle Hz | energy | clipped % | "
         "real pipeline energy |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const CyclePoint& p : result.cycles) {
    out << "| " << p.reduced_frames << " | " << text_of(p.speed_deg_s) << " | " << text_of(p.reduction) << " | "
        << fixed_text(p.pixels_saved_percent, 1) << " | " << fixed_text(p.cycle_hz, 1) << " | " << fixed_text(p.energy, 2)
        << " | " << fixed_text(p.clipped_percent, 3) << " | "
        << (std::isnan(p.pipeline_energy) ? std::string("") : fixed_text(p.pipeline_energy, 2)) << " |\n";
  }
  return out.str();
}

std::vector<std::string> write_analyze_plots(const std::string& directory, const AnalyzeResult& result) {
  const AnalyzeOptions& o = result.options;
  std::vector<std::string> written;
  const std::filesystem::path dir(directory);
  const auto energy_axis = [] {
    plot::Axis y;
    y.label = "visual difference energy";
    return y;
  };
  const auto saved_axis = [] {
    plot::Axis x;
    x.label = "pixels saved %";
    x.min = 0.0;
    x.max = 50.0;
    return x;
  };
  const std::map<std::string, std::pair<std::string, std::string>> names{
      {"contrast", {"Fig. 2: varying contrast", "contrast"}},
      {"ppd", {"Fig. 3: varying angular resolution", "ppd"}},
      {"refresh", {"Fig. 4: varying refresh rate", "Hz"}}};
  for (const char* parameter : {"contrast", "ppd", "refresh"}) {
    plot::Figure figure;
    figure.title = names.at(parameter).first;
    figure.subtitle = settings_line(result) + "; labels: r";
    for (double speed : o.speeds) {
      plot::Chart chart;
      chart.title = text_of(speed) + " deg/s";
      chart.x = saved_axis();
      chart.y = energy_axis();
      bool labelled = false;
      for (const auto& curve : curves_of(result, parameter, speed)) {
        plot::Series s;
        s.label = text_of(curve.front()->value) + " " + names.at(parameter).second;
        s.style = plot::Style::LineAndPoints;
        for (const StudyPoint* p : curve) {
          s.x.push_back(p->pixels_saved_percent);
          s.y.push_back(p->energy);
          if (!labelled) s.point_labels.push_back(text_of(p->reduction, 2));
        }
        labelled = true;
        chart.series.push_back(std::move(s));
      }
      chart.legend = plot::LegendPlace::TopLeft;
      figure.charts.push_back(std::move(chart));
    }
    const std::string name = std::string("study_") + parameter + ".png";
    plot::write_png(dir / name, figure);
    written.push_back(name);
  }
  {
    plot::Figure figure;
    figure.title = "Experiment 1 predicted: smallest r under the threshold";
    figure.subtitle = text_of(o.exp1_ppd) + " ppd; threshold = energy of " + o.calibration_scene + " at " +
                      text_of(o.calibration_refresh_hz) + " Hz, r = " + text_of(o.calibration_reduction);
    plot::Chart r_chart, saved_chart;
    r_chart.title = "threshold reduction factor r";
    r_chart.x.label = "refresh rate (Hz)";
    r_chart.y.label = "r";
    r_chart.y.min = 0.0;
    r_chart.y.max = 1.0;
    saved_chart.title = "pixels saved at the threshold";
    saved_chart.x.label = "refresh rate (Hz)";
    saved_chart.y.label = "pixels saved %";
    saved_chart.y.min = 0.0;
    saved_chart.y.max = 50.0;
    for (const std::string& scene : o.scenes) {
      plot::Series r, saved;
      r.label = saved.label = scene;
      r.style = saved.style = plot::Style::LineAndPoints;
      for (const Exp1Point& p : result.exp1) {
        if (p.scene != scene) continue;
        r.x.push_back(p.refresh_hz);
        r.y.push_back(p.threshold_reduction);
        saved.x.push_back(p.refresh_hz);
        saved.y.push_back(p.pixels_saved_percent());
      }
      r_chart.series.push_back(std::move(r));
      saved_chart.series.push_back(std::move(saved));
    }
    plot::Series paper;
    paper.label = "paper: r 0.4 indistinguishable";
    paper.dashed = true;
    paper.x = {o.exp1_refreshes.front(), o.exp1_refreshes.back()};
    paper.y = {0.4, 0.4};
    r_chart.series.push_back(paper);
    figure.charts.push_back(std::move(r_chart));
    figure.charts.push_back(std::move(saved_chart));
    plot::write_png(dir / "experiment1.png", figure);
    written.push_back("experiment1.png");
  }
  {
    plot::Figure figure;
    figure.title = "1 full + k reduced frames (supplement §1.4)";
    figure.subtitle = settings_line(result) + " (here " + std::to_string(result.cycle_frames) + ", whole cycles); " +
                      text_of(o.ppd) + " ppd, " + text_of(o.pipeline.refresh_hz) + " Hz, contrast " + text_of(o.contrast);
    for (double speed : o.speeds) {
      plot::Chart chart;
      chart.title = text_of(speed) + " deg/s";
      chart.x.label = "pixels saved %";
      chart.x.min = 0.0;
      chart.x.max = 100.0;
      chart.y = energy_axis();
      for (int k : o.cycles) {
        plot::Series s;
        s.label = "1 + " + std::to_string(k) + " (" + text_of(o.pipeline.refresh_hz / (k + 1.0), 3) + " Hz cycle)";
        s.style = plot::Style::LineAndPoints;
        for (const CyclePoint& p : result.cycles) {
          if (p.reduced_frames != k || p.speed_deg_s != speed) continue;
          s.x.push_back(p.pixels_saved_percent);
          s.y.push_back(p.energy);
        }
        chart.series.push_back(std::move(s));
      }
      chart.legend = plot::LegendPlace::TopLeft;
      figure.charts.push_back(std::move(chart));
    }
    plot::write_png(dir / "cycles.png", figure);
    written.push_back("cycles.png");
  }
  return written;
}

}  // namespace trm::cli
