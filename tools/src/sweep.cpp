#include "sweep.hpp"

#include "hw_report.hpp"

#include "trm/panel.hpp"
#include "trm/plot.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A knob that is one int field of the configuration.
SweepKnob field_knob(std::string name, std::string description, std::string cost, std::vector<int> values,
                     int FixedDecoderConfig::*field, bool oled = true, bool lcd = true) {
  SweepKnob k;
  k.name = std::move(name);
  k.description = std::move(description);
  k.cost = std::move(cost);
  k.values = std::move(values);
  k.oled = oled;
  k.lcd = lcd;
  k.get = [field](const FixedDecoderConfig& c) { return c.*field; };
  k.set = [field](FixedDecoderConfig& c, int v) { c.*field = v; };
  return k;
}

std::vector<SweepKnob> make_knobs() {
  std::vector<SweepKnob> knobs;
  SweepKnob linear = field_knob(
      "linear_frac_bits", "linear light I, L, alpha, beta: uQ1.F (the residual store follows when it is lossless)",
      "ROM words, frame stores (residual, LCD x_{t-1}), arithmetic", {16, 18, 20, 21, 22, 23, 24, 26, 28},
      &FixedDecoderConfig::linear_frac_bits);
  linear.set = [](FixedDecoderConfig& c, int v) {
    // The default residual store is lossless (sQ2.F): keep it so, so that this knob measures linear light alone.
    if (c.residual.frac_bits == c.linear_frac_bits) c.residual.frac_bits = v;
    c.linear_frac_bits = v;
  };
  knobs.push_back(std::move(linear));
  knobs.push_back(field_knob("gaussian_tap_frac_bits", "D (polyphase Gaussian) taps uQ0.T, summing to 2^T",
                             "arithmetic width only", {10, 12, 14, 16, 18, 20, 22, 24, 26, 28},
                             &FixedDecoderConfig::gaussian_tap_frac_bits));
  knobs.push_back(field_knob("gaussian_line_frac_bits", "D vertical line buffer: horizontal results in codes uQb.L",
                             "line buffer (vertical Gaussian)", {0, 2, 4, 6, 8, 10, 12, 14, 16, 20, 24},
                             &FixedDecoderConfig::gaussian_line_frac_bits));
  SweepKnob linear_resample = field_knob(
      "linear_resample_frac_bits",
      "linear resample space: lin(E) ROM words and D's input uQ1.P (--resample-space linear only)",
      "ROM (lin(E) per link code), line buffer (vertical Gaussian)", {16, 20, 24, 26, 28, 30, 32, 36, 40},
      &FixedDecoderConfig::linear_resample_frac_bits);
  linear_resample.linear_space_only = true;
  knobs.push_back(std::move(linear_resample));
  SweepKnob linear_taps = field_knob("linear_gaussian_tap_frac_bits",
                                     "linear resample space: D taps uQ0.T, summing to 2^T (--resample-space linear only)",
                                     "arithmetic width only", {8, 12, 16, 20, 24, 28, 30},
                                     &FixedDecoderConfig::linear_gaussian_tap_frac_bits);
  linear_taps.linear_space_only = true;
  knobs.push_back(std::move(linear_taps));
  knobs.push_back(field_knob("bilinear_weight_frac_bits", "U (bilinear) weights uQ0.W", "arithmetic width only",
                             {4, 6, 8, 10, 12, 14, 16, 20, 24}, &FixedDecoderConfig::bilinear_weight_frac_bits));
  knobs.push_back(field_knob("upsample_frac_bits", "U output in codes uQb.U (EOTF ROM address + interpolation weight)",
                             "arithmetic width only", {4, 8, 12, 14, 16, 20, 24, 28, 32},
                             &FixedDecoderConfig::upsample_frac_bits));
  knobs.push_back(field_knob("eotf_segments_per_code_log2",
                             "EOTF LUT after U: 2^k segments per code step, (2^b - 1) 2^k + 1 words", "ROM (EOTF)",
                             {0, 1, 2, 3, 4, 5, 6, 7, 8}, &FixedDecoderConfig::eotf_segments_per_code_log2));
  SweepKnob residual;
  residual.name = "residual_bits";
  residual.description = "residual store rho: N bits, sQ2.(N - 2) (as --residual-bits)";
  residual.cost = "frame store (residual)";
  residual.values = {4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30};
  residual.get = [](const FixedDecoderConfig& c) { return c.residual.width(); };
  residual.set = [](FixedDecoderConfig& c, int v) { c.residual = residual_format_of_bits(v, c.linear_frac_bits); };
  knobs.push_back(std::move(residual));
  knobs.push_back(field_knob("luma_weight_frac_bits", "Eq. 5 Rec. 709 luma weights uQ0.W, summing to 2^W",
                             "arithmetic width only", {8, 10, 12, 14, 16, 20, 24, 28},
                             &FixedDecoderConfig::luma_weight_frac_bits));
  knobs.push_back(field_knob("reciprocal_entries", "Eq. 5 1/(Y_prev + Y_alpha): normalised reciprocal LUT words",
                             "ROM (reciprocal)", {65, 129, 257, 513, 1025, 2049, 4097},
                             &FixedDecoderConfig::reciprocal_entries));
  knobs.push_back(field_knob("sensitivity_frac_bits", "Eq. 6 motion sensitivity s as uQ8.S",
                             "arithmetic width only", {4, 8, 12, 16, 20, 24},
                             &FixedDecoderConfig::sensitivity_frac_bits));
  knobs.push_back(field_knob("exp_input_frac_bits", "Eq. 6 x = s c as uQ5.X (the exp LUT address)",
                             "arithmetic width only", {8, 10, 12, 14, 16, 18, 20, 24},
                             &FixedDecoderConfig::exp_input_frac_bits));
  knobs.push_back(field_knob("exp_entries", "Eq. 6 exp(-f), f in [0, 1): interpolated LUT words", "ROM (exp)",
                             {65, 129, 257, 513, 1025, 2049, 4097, 8193}, &FixedDecoderConfig::exp_entries));
  knobs.push_back(field_knob("drive_frac_bits",
                             "OLED drive value v (DecodedFrame::drive, reports only; codes come from thresholds): "
                             "uQ1.D",
                             "none (report path)", {8, 10, 12, 14, 16, 20, 24}, &FixedDecoderConfig::drive_frac_bits,
                             true, false));
  knobs.push_back(field_knob("drive_segments_per_octave",
                             "OLED drive value LUT x^(1/gamma): segments per octave (reports only)",
                             "none (report path)", {1, 2, 4, 8, 16, 32, 64, 128},
                             &FixedDecoderConfig::drive_segments_per_octave, true, false));
  knobs.push_back(field_knob("lcd_segments_per_octave", "LCD target m = x^(1/gamma) LUT: segments per octave",
                             "ROM (LCD target)", {8, 16, 32, 64, 128, 256, 512, 1024, 2048},
                             &FixedDecoderConfig::lcd_segments_per_octave, false, true));
  return knobs;
}

std::string knob_list() {
  std::string list;
  for (const auto& k : sweep_knobs()) {
    if (!list.empty()) list.append(", ");
    list.append(k.name);
  }
  return list;
}

// Why a knob does nothing for this panel and resample space, or empty when it applies.
std::string not_applicable(const SweepKnob& knob, PanelKind kind, ResampleSpace space) {
  if (kind == PanelKind::Lcd && !knob.lcd) return "not used with the LCD panel";
  if (kind == PanelKind::Oled && !knob.oled) return "used with the LCD panel only";
  if (knob.linear_space_only && space != ResampleSpace::Linear) return "used with --resample-space linear only";
  return "";
}

// One recorded view per pixel: link codes and drive codes (CV_16UC3, 6 B each), drive and emitted light
// (CV_64FC3, 24 B each).
constexpr double kRecordedViewBytesPerPixel = 6.0 + 6.0 + 24.0 + 24.0;

// The reference's output of one view, and the view as sent.
struct RecordedView {
  LinkFrame sent;
  cv::Mat drive_codes;
  cv::Mat drive;
  cv::Mat emitted;
};

struct Recording {
  std::vector<RecordedView> views;
  double reference_seconds = 0.0;
  cv::Size size, reduced;
};

Recording record_reference(const PipelineOptions& pipeline) {
  PipelineOptions options = pipeline;
  options.impl = "reference";
  options.compare_reference = false;
  Recording rec;
  run_pipeline(options, [&](const DecodedView& view) {
    RecordedView v;
    v.sent = LinkFrame{view.sent->meta, view.sent->codes.clone()};
    v.drive_codes = view.decoded->drive_codes.clone();
    v.drive = view.decoded->drive.clone();
    v.emitted = view.decoded->emitted_linear.clone();
    rec.reference_seconds += view.decode_seconds;
    const FrameMeta& m = view.sent->meta;
    rec.size = cv::Size(m.full_width, m.full_height);
    if (m.parity == Parity::Reduced) rec.reduced = cv::Size(m.width, m.height);
    rec.views.push_back(std::move(v));
  });
  if (rec.views.empty()) throw std::runtime_error("the sweep's sequence has no frames");
  return rec;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Decodes the recorded sequence `repeats` times with a fresh streaming decoder of this configuration.
SweepPoint evaluate(const FixedDecoderConfig& config, const Recording& rec, const SweepOptions& options,
                    const std::function<void()>& sequence_done) {
  SweepPoint p;
  p.residual_format = config.residual.to_string();
  const double levels = std::ldexp(1.0, config.decoder.output_bits) - 1.0;
  double sum_lsb = 0.0, sum_sq_lsb = 0.0, sum_sq_linear = 0.0;
  std::int64_t linear_samples = 0;
  // Decode time of every view in every repeat: the median per view over the repeats, averaged over the views.
  std::vector<std::vector<double>> view_seconds(rec.views.size());
  for (int repeat = 0; repeat < options.repeats; ++repeat) {
    const auto setup_start = Clock::now();
    std::unique_ptr<HeadsetDecoder> decoder;
    try {
      decoder = make_decoder("fixed", config);  // the hardware model
    } catch (const std::invalid_argument& e) {
      p.status = "rejected";
      p.message = e.what();
      return p;
    }
    if (repeat == 0) {
      p.setup_seconds = seconds_since(setup_start);
      FixedStreamingReport hardware;
      if (!decoder->hardware_report(options.hw_size, hardware)) throw std::logic_error("the sweep needs a hardware model");
      const Json totals = hardware_json(hardware)["totals"];
      p.on_chip_bits = totals["on_chip_bits"].get<std::int64_t>();
      p.off_chip_bits = totals["off_chip_bits"].get<std::int64_t>();
    }
    double decode_seconds = 0.0;
    for (std::size_t i = 0; i < rec.views.size(); ++i) {
      const RecordedView& view = rec.views[i];
      DecodedFrame decoded;
      try {
        const auto start = Clock::now();
        decoded = decoder->decode(view.sent);
        const double seconds = seconds_since(start);
        decode_seconds += seconds;
        view_seconds[i].push_back(seconds);
      } catch (const std::exception& e) {
        p.status = "failed";
        p.message = std::string("decoding frame ").append(std::to_string(view.sent.meta.index)).append(": ").append(
            e.what());
        return p;
      }
      if (repeat > 0) continue;
      const FixedStageCounts& counts = *decoder->stage_counts();
      p.residual_saturated += counts.residual_saturated;
      p.residual_rounded += counts.residual_rounded;
      cv::Mat difference;
      cv::absdiff(decoded.drive_codes, view.drive_codes, difference);
      cv::Mat flat;
      difference.reshape(1).convertTo(flat, CV_64F);
      p.codes += static_cast<std::int64_t>(flat.total());
      p.differing += cv::countNonZero(flat);
      p.max_lsb = std::max(p.max_lsb, cv::norm(flat, cv::NORM_INF));
      sum_lsb += cv::sum(flat)[0];
      sum_sq_lsb += cv::norm(flat, cv::NORM_L2SQR);
      p.linear_max = std::max(p.linear_max, cv::norm(decoded.emitted_linear, view.emitted, cv::NORM_INF));
      sum_sq_linear += cv::norm(decoded.emitted_linear, view.emitted, cv::NORM_L2SQR);
      linear_samples += static_cast<std::int64_t>(view.emitted.total()) * view.emitted.channels();
      p.drive_max_lsb = std::max(p.drive_max_lsb, cv::norm(decoded.drive, view.drive, cv::NORM_INF) * levels);
    }
    p.repeat_seconds_per_frame.push_back(decode_seconds / static_cast<double>(rec.views.size()));
    if (sequence_done) sequence_done();
  }
  const auto codes = static_cast<double>(p.codes);
  p.identical_percent = 100.0 * static_cast<double>(p.codes - p.differing) / codes;
  p.mean_lsb = sum_lsb / codes;
  p.rms_lsb = std::sqrt(sum_sq_lsb / codes);
  p.linear_rms = std::sqrt(sum_sq_linear / static_cast<double>(linear_samples));
  for (const auto& seconds : view_seconds) {
    p.seconds_per_frame += median(seconds);
    p.min_seconds_per_frame += *std::min_element(seconds.begin(), seconds.end());
  }
  p.seconds_per_frame /= static_cast<double>(view_seconds.size());
  p.min_seconds_per_frame /= static_cast<double>(view_seconds.size());
  return p;
}

// ---- text formatting ----

std::string fixed_text(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string general(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

std::string scientific(double v) {
  if (v == 0.0) return "0";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2e", v);
  return buffer;
}

// Identical share, rounded down so that anything short of all codes never reads as 100 %.
std::string percent_text(const SweepPoint& p) {
  if (p.differing == 0) return "100 %";
  return fixed_text(std::floor(p.identical_percent * 1e4) / 1e4, 4) + " %";
}

std::string kib(std::int64_t bits) { return fixed_text(static_cast<double>(bits) / 8.0 / 1024.0, 1); }

std::string signed_kib(std::int64_t bits) {
  if (bits == 0) return "0";
  return std::string(bits > 0 ? "+" : "−").append(kib(std::abs(bits)));
}

std::string ms(double seconds) { return fixed_text(seconds * 1e3, 2); }

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out.push_back('"');
    out.push_back(c == '\n' ? ' ' : c);
  }
  out.push_back('"');
  return out;
}

std::string md_cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out.append("\\|"); else out.push_back(c);
  }
  return out;
}

std::string value_text(const SweepPoint& p) {
  if (!p.is_default) return std::to_string(p.value);
  return std::string("**").append(std::to_string(p.value)).append("** (base)");
}

std::string source_text(const SweepOptions& o) {
  return o.pipeline.input.empty() ? o.pipeline.scene : o.pipeline.input;
}

std::string header_line(const SweepResult& r) {
  std::ostringstream s;
  const auto& o = r.options.pipeline;
  s << source_text(r.options) << " " << r.size.width << "x" << r.size.height << " (reduced " << r.reduced.width << "x"
    << r.reduced.height << "), " << r.views << " views, r = " << o.encoder.reduction << ", " << o.panel << ", "
    << o.encoder.bits << "-bit link, " << o.output_bits << "-bit drive";
  return s.str();
}

// ---- plots ----

// A knob's values, memory or times as an axis: logarithmic when all positive and spanning a factor of 8 or more.
plot::Axis spread_axis(const std::vector<double>& values, std::string label) {
  plot::Axis a;
  a.label = std::move(label);
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  if (*lo > 0 && *hi / *lo >= 8.0) a.scale = plot::Scale::Log;
  return a;
}

}  // namespace

const std::vector<SweepKnob>& sweep_knobs() {
  static const std::vector<SweepKnob> knobs = make_knobs();
  return knobs;
}

const SweepKnob* find_sweep_knob(const std::string& name) {
  for (const auto& k : sweep_knobs()) {
    if (k.name == name) return &k;
  }
  return nullptr;
}

void SweepOptions::validate() const {
  for (const auto& name : knobs) {
    if (!find_sweep_knob(name)) {
      throw std::invalid_argument(std::string("unknown knob '").append(name).append("' (available: ").append(
          knob_list()).append(")"));
    }
  }
  if (!values.empty() && knobs.size() != 1) {
    throw std::invalid_argument("--values needs exactly one --knob (the values of one knob)");
  }
  if (repeats < 1) throw std::invalid_argument("--repeats must be >= 1");
  if (hw_size.width < 1 || hw_size.height < 1) throw std::invalid_argument("--hw-size must be WxH with W, H >= 1");
  pipeline.validate();
  // The recording keeps every view's codes, drive codes, drive and emitted light beside a pipeline run.
  const std::int64_t frames = pipeline.frames > 0 ? pipeline.frames : pipeline.default_frames;
  const std::int64_t views = frames * (pipeline.encoder.stereo ? 2 : 1);
  require_memory("for the pipeline and " + std::to_string(views) + " recorded views",
                 run_bytes_per_pixel(pipeline) + kRecordedViewBytesPerPixel * static_cast<double>(views),
                 cv::Size(pipeline.width, pipeline.height));
}

const SweepPoint* SweepKnobResult::cheapest_meeting() const {
  // Points ascend in value, and every knob costs more (or the same) as it grows: scan down from the most precise
  // accepted value while the criterion holds.
  const SweepPoint* best = nullptr;
  for (auto it = points.rbegin(); it != points.rend(); ++it) {
    if (!it->ok()) continue;
    if (!it->meets_criterion()) break;
    best = &*it;
  }
  return best;
}

SweepResult run_sweep(const SweepOptions& options,
                      const std::function<void(std::int64_t done, std::int64_t total)>& progress) {
  options.validate();
  const Panel panel = parse_panel(options.pipeline.panel);
  const FixedDecoderConfig base = fixed_config_of(options.pipeline);
  (void)make_decoder("fixed", base);  // an unusable base configuration fails the whole sweep, with its message

  SweepResult result;
  result.options = options;
  std::vector<const SweepKnob*> chosen;
  for (const auto& knob : sweep_knobs()) {
    const bool asked = options.knobs.empty() ||
                       std::find(options.knobs.begin(), options.knobs.end(), knob.name) != options.knobs.end();
    if (asked) chosen.push_back(&knob);
  }
  // The values of every chosen knob that applies, base value included (ascending, distinct).
  std::vector<std::vector<int>> values(chosen.size());
  std::int64_t decodes = 1;  // the base point
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (!not_applicable(*chosen[i], panel.kind, options.pipeline.encoder.resample_space).empty()) continue;
    std::set<int> set(options.values.empty() ? chosen[i]->values.begin() : options.values.begin(),
                      options.values.empty() ? chosen[i]->values.end() : options.values.end());
    set.insert(chosen[i]->get(base));
    values[i].assign(set.begin(), set.end());
    decodes += static_cast<std::int64_t>(values[i].size()) - 1;
  }

  const auto start = Clock::now();
  const Recording rec = record_reference(options.pipeline);
  result.size = rec.size;
  result.reduced = rec.reduced;
  result.views = static_cast<std::int64_t>(rec.views.size());
  result.reference_seconds_per_frame = rec.reference_seconds / static_cast<double>(result.views);
  const std::int64_t total = result.views * (1 + decodes * options.repeats);
  std::int64_t done = result.views;
  const auto sequence_done = [&] {
    done += result.views;
    if (progress) progress(done, total);
  };
  if (progress) progress(done, total);

  // One untimed decode of the sequence first, so that the base point is not timed on cold caches.
  (void)evaluate(base, rec, [&] {
    SweepOptions once = options;
    once.repeats = 1;
    return once;
  }(), {});
  result.base = evaluate(base, rec, options, sequence_done);
  result.base.is_default = true;
  if (!result.base.ok()) {
    throw std::runtime_error(std::string("the base configuration failed: ").append(result.base.message));
  }

  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const SweepKnob& knob = *chosen[i];
    SweepKnobResult kr;
    kr.knob = &knob;
    kr.default_value = knob.get(base);
    kr.skipped = not_applicable(knob, panel.kind, options.pipeline.encoder.resample_space);
    if (!kr.skipped.empty()) {
      result.knobs.push_back(std::move(kr));
      continue;
    }
    for (int value : values[i]) {
      SweepPoint p;
      if (value == kr.default_value) {
        p = result.base;
      } else {
        FixedDecoderConfig config = base;
        bool set = true;
        try {
          knob.set(config, value);
        } catch (const std::invalid_argument& e) {
          p.status = "rejected";
          p.message = e.what();
          set = false;
        }
        if (set) p = evaluate(config, rec, options, sequence_done);
        if (!p.ok()) {
          done += result.views * options.repeats - static_cast<std::int64_t>(p.repeat_seconds_per_frame.size()) *
                                                       result.views;
          if (progress) progress(done, total);
        }
        p.is_default = false;
      }
      p.value = value;
      if (p.ok()) {
        p.delta_on_chip_bits = p.on_chip_bits - result.base.on_chip_bits;
        p.delta_off_chip_bits = p.off_chip_bits - result.base.off_chip_bits;
      }
      kr.points.push_back(std::move(p));
    }
    if (!options.values.empty()) {
      // Asked-for values that all fail leave nothing to report: an error, with the first reason.
      const SweepPoint* first_failure = nullptr;
      bool any_asked_ok = false;
      for (const SweepPoint& p : kr.points) {
        if (p.is_default) continue;
        if (p.ok()) any_asked_ok = true;
        else if (!first_failure) first_failure = &p;
      }
      if (!any_asked_ok && first_failure) {
        throw std::invalid_argument("--values: every value asked for " + knob.name + " was rejected (" +
                                    std::to_string(first_failure->value) + ": " + first_failure->message + ")");
      }
    }
    result.knobs.push_back(std::move(kr));
  }
  result.wall_seconds = seconds_since(start);
  return result;
}

std::string sweep_csv(const SweepResult& r) {
  const std::vector<std::string> columns = {
      "knob", "value", "is_default", "status", "message", "identical_percent", "differing_codes", "codes", "max_lsb",
      "mean_lsb", "rms_lsb", "linear_max", "linear_rms", "drive_max_lsb", "residual_saturated", "residual_rounded",
      "seconds_per_frame", "min_seconds_per_frame", "reference_seconds_per_frame", "setup_seconds", "on_chip_bits",
      "off_chip_bits", "delta_on_chip_bits", "delta_off_chip_bits", "residual_format", "meets_criterion"};
  std::ostringstream s;
  const auto row = [&s](const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) s << (i ? "," : "") << csv_field(fields[i]);
    s << "\n";
  };
  row(columns);
  for (const auto& k : r.knobs) {
    for (const auto& p : k.points) {
      std::vector<std::string> f = {k.knob->name, std::to_string(p.value), p.is_default ? "1" : "0", p.status,
                                    p.message};
      if (p.ok()) {
        for (const std::string& v :
             {general(p.identical_percent), std::to_string(p.differing), std::to_string(p.codes), general(p.max_lsb),
              general(p.mean_lsb), general(p.rms_lsb), general(p.linear_max), general(p.linear_rms),
              general(p.drive_max_lsb), std::to_string(p.residual_saturated), std::to_string(p.residual_rounded),
              general(p.seconds_per_frame), general(p.min_seconds_per_frame), general(r.reference_seconds_per_frame),
              general(p.setup_seconds), std::to_string(p.on_chip_bits), std::to_string(p.off_chip_bits),
              std::to_string(p.delta_on_chip_bits), std::to_string(p.delta_off_chip_bits), p.residual_format}) {
          f.push_back(v);
        }
      }
      f.resize(columns.size() - 1);
      f.push_back(p.meets_criterion() ? "1" : "0");
      row(f);
    }
  }
  return s.str();
}

namespace {

std::string summary_table_md(const SweepResult& r) {
  std::ostringstream s;
  s << "| knob | base | range | cheapest value meeting the criterion | identical | max | on-chip KiB | off-chip KiB "
       "| Δ memory KiB | decode ms/frame | min ms |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& k : r.knobs) {
    if (!k.skipped.empty()) continue;
    const SweepPoint* c = k.cheapest_meeting();
    s << "| `" << k.knob->name << "` | " << k.default_value << " | " << k.points.front().value << "–"
      << k.points.back().value << " | ";
    if (c) {
      s << c->value << " | " << percent_text(*c) << " | " << general(c->max_lsb) << " | " << kib(c->on_chip_bits)
        << " | " << kib(c->off_chip_bits) << " | " << signed_kib(c->delta_on_chip_bits + c->delta_off_chip_bits)
        << " | " << ms(c->seconds_per_frame) << " | " << ms(c->min_seconds_per_frame) << " |\n";
    } else {
      s << "none | | | | | | | |\n";
    }
  }
  return s.str();
}

}  // namespace

std::string sweep_markdown(const SweepResult& r) {
  std::ostringstream s;
  const auto& o = r.options;
  s << "# Fixed-point decoder: error against run time and memory\n\n";
  s << "Regenerate with `" << o.command << "`.\n\n";
  s << "* sequence: " << header_line(r) << "; every knob swept alone, the others at the base configuration "
       "(the default formats, residual " << r.base.residual_format << ")\n";
  s << "* error: output drive codes of the streaming fixed-point decoder against the double-precision reference "
       "rounded to the output depth (identical share, max / mean / RMS |Δ| in output LSB); linear light emitted "
       "from those codes by the panel model (max and RMS |Δ|); drive value v before quantisation (max |Δ|, output "
       "LSB)\n";
  s << "* time: decode wall time per view (steady clock), the median over " << o.repeats
    << " decode(s) of the sequence per view, averaged over the views (min ms: each view's fastest decode instead, "
       "the figure least disturbed by other load, plotted); the reference decoder took "
    << ms(r.reference_seconds_per_frame) << " ms per view (one decode)\n";
  s << "* memory: `FixedStreamingDecoder::report()` at " << o.hw_size.width << "x" << o.hw_size.height
    << ": on chip = line buffers + ROMs, off chip = frame stores; base " << kib(r.base.on_chip_bits) << " KiB on chip, "
    << kib(r.base.off_chip_bits) << " KiB off chip; Δ memory = on + off chip against the base\n";
  s << "* criterion (DESIGN §6): ≥ " << kSweepIdenticalPercent << " % identical codes and max |Δ| ≤ "
    << kSweepMaxLsb << " LSB; the cheapest value meeting it is the smallest value at and above which every "
       "accepted value meets it (every knob costs the same or more as it grows, and a value that passes below a "
       "failing one is not taken)\n\n";
  s << "## Summary\n\n" << summary_table_md(r) << "\n";
  for (const auto& k : r.knobs) {
    s << "## `" << k.knob->name << "`\n\n" << k.knob->description << ". Cost: " << k.knob->cost << ".\n\n";
    if (!k.skipped.empty()) {
      s << "Skipped: " << k.skipped << ".\n\n";
      continue;
    }
    s << "![" << k.knob->name << "](sweep_" << k.knob->name << ".png)\n\n";
    s << "| value | identical | max | mean | RMS | linear max | linear RMS | drive v max | ms/frame | min ms "
         "| on-chip KiB | off-chip KiB | Δ memory KiB | meets |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& p : k.points) {
      s << "| " << value_text(p) << " | ";
      if (!p.ok()) {
        s << p.status << ": " << md_cell(p.message) << " | | | | | | | | | | | | |\n";
        continue;
      }
      s << percent_text(p) << " | " << general(p.max_lsb) << " | " << scientific(p.mean_lsb) << " | "
        << scientific(p.rms_lsb) << " | " << scientific(p.linear_max) << " | " << scientific(p.linear_rms) << " | "
        << fixed_text(p.drive_max_lsb, 3) << " | " << ms(p.seconds_per_frame) << " | " << ms(p.min_seconds_per_frame)
        << " | " << kib(p.on_chip_bits) << " | "
        << kib(p.off_chip_bits) << " | " << signed_kib(p.delta_on_chip_bits + p.delta_off_chip_bits) << " | "
        << (p.meets_criterion() ? "yes" : "no") << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

Json sweep_json(const SweepResult& r) {
  const auto& o = r.options;
  const auto& po = o.pipeline;
  Json j;
  j["tool"] = "trm sweep";
  j["command"] = o.command;
  j["parameters"] = {{"source", source_text(o)},
                     {"size", {r.size.width, r.size.height}},
                     {"reduced_size", {r.reduced.width, r.reduced.height}},
                     {"views", r.views},
                     {"reduction", po.encoder.reduction},
                     {"sigma", po.encoder.effective_sigma()},
                     {"transfer", to_string(po.encoder.transfer)},
                     {"link_bits", po.encoder.bits},
                     {"output_bits", po.output_bits},
                     {"stereo", po.encoder.stereo},
                     {"sensitivity", po.sensitivity},
                     {"panel", po.panel},
                     {"seed", po.seed},
                     {"repeats", o.repeats},
                     {"hw_size", {o.hw_size.width, o.hw_size.height}}};
  j["criterion"] = {{"identical_percent_at_least", kSweepIdenticalPercent}, {"max_lsb_at_most", kSweepMaxLsb}};
  j["reference_seconds_per_frame"] = r.reference_seconds_per_frame;
  const auto point_json = [&](const SweepPoint& p) {
    Json pj;
    pj["value"] = p.value;
    pj["is_default"] = p.is_default;
    pj["status"] = p.status;
    if (!p.ok()) {
      pj["message"] = p.message;
      return pj;
    }
    pj["error"] = {{"codes", p.codes},
                   {"differing_codes", p.differing},
                   {"identical_percent", p.identical_percent},
                   {"max_lsb", p.max_lsb},
                   {"mean_lsb", p.mean_lsb},
                   {"rms_lsb", p.rms_lsb},
                   {"linear_max", p.linear_max},
                   {"linear_rms", p.linear_rms},
                   {"drive_max_lsb", p.drive_max_lsb}};
    pj["residual_events"] = {{"saturated", p.residual_saturated}, {"rounded", p.residual_rounded}};
    pj["time"] = {{"seconds_per_frame", p.seconds_per_frame},
                  {"min_seconds_per_frame", p.min_seconds_per_frame},
                  {"repeat_seconds_per_frame", p.repeat_seconds_per_frame},
                  {"setup_seconds", p.setup_seconds}};
    pj["memory"] = {{"on_chip_bits", p.on_chip_bits},
                    {"off_chip_bits", p.off_chip_bits},
                    {"delta_on_chip_bits", p.delta_on_chip_bits},
                    {"delta_off_chip_bits", p.delta_off_chip_bits}};
    pj["residual_format"] = p.residual_format;
    pj["meets_criterion"] = p.meets_criterion();
    return pj;
  };
  j["base"] = point_json(r.base);
  Json knobs = Json::array();
  for (const auto& k : r.knobs) {
    Json kj;
    kj["name"] = k.knob->name;
    kj["description"] = k.knob->description;
    kj["cost"] = k.knob->cost;
    kj["base_value"] = k.default_value;
    if (!k.skipped.empty()) {
      kj["skipped"] = k.skipped;
    } else {
      const SweepPoint* c = k.cheapest_meeting();
      kj["cheapest_meeting_criterion"] = c ? Json(c->value) : Json(nullptr);
      Json points = Json::array();
      for (const auto& p : k.points) points.push_back(point_json(p));
      kj["points"] = std::move(points);
    }
    knobs.push_back(std::move(kj));
  }
  j["knobs"] = std::move(knobs);
  j["wall_seconds"] = r.wall_seconds;
  return j;
}

void write_sweep_plot(const std::filesystem::path& path, const SweepResult& r, const SweepKnobResult& k) {
  std::vector<const SweepPoint*> points;
  for (const auto& p : k.points) {
    if (p.ok()) points.push_back(&p);
  }
  plot::Figure figure;
  figure.width = 1620;
  figure.height = 500;
  figure.title = k.knob->name;
  figure.title.append(": ").append(k.knob->description);
  figure.subtitle = header_line(r);
  figure.subtitle.append("; memory at ").append(std::to_string(r.options.hw_size.width)).append("x").append(
      std::to_string(r.options.hw_size.height));
  const int rejected = static_cast<int>(k.points.size() - points.size());
  if (rejected > 0) {
    figure.subtitle.append("; ").append(std::to_string(rejected)).append(" value(s) rejected, not drawn");
  }
  if (points.empty()) {
    plot::Chart chart;
    chart.note = "no value of this knob was accepted";
    figure.charts = {chart};
    plot::write_png(path, figure);
    return;
  }

  bool on_varies = false, off_varies = false;
  for (const SweepPoint* p : points) {
    on_varies = on_varies || p->on_chip_bits != points.front()->on_chip_bits;
    off_varies = off_varies || p->off_chip_bits != points.front()->off_chip_bits;
  }
  std::vector<double> x_value, x_memory, x_time, max_lsb, rms_lsb, mean_lsb;
  std::vector<std::string> labels;
  const SweepPoint* base = nullptr;
  for (const SweepPoint* p : points) {
    if (p->is_default) base = p;
    x_value.push_back(p->value);
    const std::int64_t bits = off_varies && on_varies ? p->on_chip_bits + p->off_chip_bits
                              : off_varies            ? p->off_chip_bits
                                                      : p->on_chip_bits;
    x_memory.push_back(static_cast<double>(bits) / 8.0 / 1024.0);
    x_time.push_back(p->min_seconds_per_frame * 1e3);
    max_lsb.push_back(p->max_lsb);
    rms_lsb.push_back(p->rms_lsb);
    mean_lsb.push_back(p->mean_lsb);
    labels.push_back(std::to_string(p->value));
  }
  const std::string memory_label = on_varies && off_varies ? "on + off chip memory (KiB)"
                                   : off_varies            ? "off-chip memory (KiB)"
                                                           : "on-chip memory (KiB)";
  // The three errors against one x; zeros (exact agreement) sit hollow on the lower edge of the log error axis.
  const auto chart = [&](std::string title, const std::vector<double>& x, plot::Axis x_axis, plot::Style style,
                         bool value_labels) {
    plot::Chart c;
    c.title = std::move(title);
    c.x = std::move(x_axis);
    c.y.label = "error vs reference (output LSB), 0 on the lower edge";
    c.y.scale = plot::Scale::Log;
    c.y.nonpositive_on_edge = true;
    c.series = {{.label = "max |d|", .x = x, .y = max_lsb, .style = style, .colour = 3},
                {.label = "RMS |d|", .x = x, .y = rms_lsb, .style = style, .colour = 2},
                {.label = "mean |d|", .x = x, .y = mean_lsb, .style = style, .colour = 0}};
    if (value_labels) c.series.front().point_labels = labels;
    if (base) {
      const auto i = static_cast<std::size_t>(std::find(points.begin(), points.end(), base) - points.begin());
      for (const std::vector<double>* y : {&max_lsb, &rms_lsb, &mean_lsb}) c.rings.push_back({x[i], (*y)[i]});
      c.rings_label = "base value";
    }
    return c;
  };
  figure.charts = {
      chart("error vs knob value", x_value, spread_axis(x_value, k.knob->name), plot::Style::LineAndPoints, false),
      chart(on_varies || off_varies ? "error vs memory" : "error vs memory (unchanged by this knob)", x_memory,
            spread_axis(x_memory, memory_label), plot::Style::LineAndPoints, true),
      chart("error vs decode time", x_time, spread_axis(x_time, "decode time per view, ms (fastest of the repeats)"),
            plot::Style::Points, true)};
  plot::write_png(path, figure);
}

std::string sweep_summary(const SweepResult& r) {
  std::ostringstream s;
  s << "  " << header_line(r) << "\n  reference " << ms(r.reference_seconds_per_frame) << " ms/view; base "
    << percent_text(r.base) << " identical, max " << general(r.base.max_lsb) << " LSB, "
    << ms(r.base.seconds_per_frame) << " ms/view, " << kib(r.base.on_chip_bits) << " KiB on / "
    << kib(r.base.off_chip_bits) << " KiB off chip at " << r.options.hw_size.width << "x" << r.options.hw_size.height
    << "\n  cheapest value with >= " << kSweepIdenticalPercent << " % identical and max <= " << kSweepMaxLsb
    << " LSB:\n";
  s << "  " << std::left << std::setw(30) << "knob" << std::right << std::setw(6) << "base" << std::setw(10)
    << "cheapest" << std::setw(12) << "identical" << std::setw(5) << "max" << std::setw(11) << "on KiB"
    << std::setw(11) << "off KiB" << std::setw(10) << "d KiB" << std::setw(10) << "ms/view" << std::setw(9) << "min ms"
    << "\n";
  for (const auto& k : r.knobs) {
    s << "  " << std::left << std::setw(30) << k.knob->name << std::right << std::setw(6) << k.default_value;
    if (!k.skipped.empty()) {
      s << "   skipped: " << k.skipped << "\n";
      continue;
    }
    const SweepPoint* c = k.cheapest_meeting();
    if (!c) {
      s << std::setw(10) << "none" << "\n";
      continue;
    }
    std::string delta = signed_kib(c->delta_on_chip_bits + c->delta_off_chip_bits);
    if (delta.rfind("−", 0) == 0) delta = std::string("-").append(delta.substr(std::string("−").size()));
    s << std::setw(10) << c->value << std::setw(12) << percent_text(*c) << std::setw(5) << general(c->max_lsb)
      << std::setw(11) << kib(c->on_chip_bits) << std::setw(11) << kib(c->off_chip_bits) << std::setw(10) << delta
      << std::setw(10) << ms(c->seconds_per_frame) << std::setw(9) << ms(c->min_seconds_per_frame) << "\n";
  }
  return s.str();
}

}  // namespace trm::cli
