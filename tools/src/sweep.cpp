#include "sweep.hpp"
#include "elapsed.hpp"

#include "compare.hpp"
#include "hw_report.hpp"
#include "vectors.hpp"

#include "trm/metrics.hpp"
#include "trm/panel.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

namespace trm::cli {

namespace {

using Clock = std::chrono::steady_clock;

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
  k.get = [field](const SweepConfig& c) { return c.decoder.*field; };
  k.set = [field](SweepConfig& c, int v) { c.decoder.*field = v; };
  return k;
}

std::vector<SweepKnob> make_knobs() {
  std::vector<SweepKnob> knobs;
  SweepKnob linear = field_knob(
      "linear_frac_bits", "linear light I, L, alpha, beta: uQ1.F (the residual store follows when it is lossless)",
      "ROM words, frame stores (residual, LCD x_{t-1}), arithmetic", {16, 18, 20, 21, 22, 23, 24, 26, 28},
      &FixedDecoderConfig::linear_frac_bits);
  linear.set = [](SweepConfig& s, int v) {
    FixedDecoderConfig& c = s.decoder;
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
      "linear resample space: lin(E) ROM words and D's input uQ1.P (swept in that space)",
      "ROM (lin(E) per link code), line buffer (vertical Gaussian)", {16, 20, 24, 26, 28, 30, 32, 36, 40},
      &FixedDecoderConfig::linear_resample_frac_bits);
  linear_resample.linear_space_only = true;
  knobs.push_back(std::move(linear_resample));
  SweepKnob linear_taps = field_knob("linear_gaussian_tap_frac_bits",
                                     "linear resample space: D taps uQ0.T, summing to 2^T (swept in that space)",
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
  residual.get = [](const SweepConfig& c) { return c.decoder.residual.width(); };
  residual.set = [](SweepConfig& c, int v) {
    c.decoder.residual = residual_format_of_bits(v, c.decoder.linear_frac_bits);
  };
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
  // The LC model is the eye's light, not the decoder (Eq. 7's drive does not depend on it): an eye-model knob, its
  // points the base decoder's output seen through each model.
  SweepKnob lc;
  lc.name = "lc_model";
  // Short enough for a plot title; sweep.hpp (lc_model_names) says which parameters each model takes.
  lc.description = "LCD liquid-crystal model of the eye's light: first or second order (the preset's, or defaults), "
                   "without or with overdrive; held to 3";
  lc.cost = "eye-model run time (the decoder's hardware is unchanged; overdrive is the panel's)";
  lc.values = {0, 1, 2, 3};
  lc.oled = false;
  lc.eye_model = true;
  lc.lc_model = true;
  lc.value_names = lc_model_names();
  lc.get = [](const SweepConfig& c) { return lc_model_of(c.decoder.decoder.panel.lcd); };
  lc.set = [](SweepConfig& c, int v) { set_lc_model(c.decoder.decoder.panel.lcd, v); };
  knobs.push_back(std::move(lc));
  // The liquid crystal has no time step to sweep: each frame is its exact exponential segment (lc_response.hpp).
  // What is sampled within a frame is its light, by the eye's sub-steps (each integrates the light exactly and
  // takes the eye at the step's middle), so on an LCD this knob is also the sub-frame sampling of the LC light.
  SweepKnob eye;
  eye.name = "eye_substeps";
  eye.description = "eye model sub-frame steps S: the eye's motion and (LCD) the LC light's sampling within a frame; "
                    "S divides " + std::to_string(kExactEyeSubsteps);
  eye.cost = "eye-model run time (no hardware)";
  eye.values = {1, 2, 4, 8, 16, 32, 64, 128};
  eye.eye_model = true;
  eye.get = [](const SweepConfig& c) { return c.eye_substeps; };
  eye.set = [](SweepConfig& c, int v) {
    if (v < 1 || kExactEyeSubsteps % v != 0) {
      throw std::invalid_argument("eye_substeps " + std::to_string(v) + " does not divide the exact eye's " +
                                  std::to_string(kExactEyeSubsteps) + " sub-steps");
    }
    c.eye_substeps = v;
  };
  knobs.push_back(std::move(eye));
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

// Why a knob does nothing for this panel, or empty when it applies.
std::string not_applicable(const SweepKnob& knob, const Panel& panel) {
  if (panel.has_history() && !knob.lcd) return "not used with the LCD panel";
  if (!panel.has_history() && !knob.oled) return "used with the LCD panel only";
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

// The recording as the points see it: every view as sent and the reference's drive codes.
std::uint64_t recording_hash(const Recording& rec) {
  std::string digests;
  const auto add = [&digests](const cv::Mat& image) {
    const cv::Mat continuous = image.isContinuous() ? image : image.clone();
    const std::uint64_t digest = fnv1a64(std::string(reinterpret_cast<const char*>(continuous.data),
                                                     continuous.total() * continuous.elemSize()));
    digests.append(reinterpret_cast<const char*>(&digest), sizeof digest);
  };
  for (const RecordedView& view : rec.views) {
    add(view.sent.codes);
    add(view.drive_codes);
  }
  return fnv1a64(digests);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// One encoded sequence with its reference decoding, its base point and what the eye makes of the reference.
struct Sequence {
  Recording rec;
  SweepConfig base_config;
  SweepPoint base;
  std::vector<ShownFrame> base_shown;       // the base decoder's frames of eye 0
  PerceivedSequence reference_seen;         // the reference decoder's, at the base eye
};

std::vector<ShownFrame> reference_shown(const Recording& rec) {
  std::vector<ShownFrame> shown;
  for (const RecordedView& view : rec.views) {
    if (view.sent.meta.eye == 0) shown.push_back({view.sent.meta.index, view.drive_codes});
  }
  return shown;
}

// The perceived error and eye-model time of `shown` at `substeps` against `reference`, perceived `runs` times.
void watch(SweepPoint& p, const std::vector<ShownFrame>& shown, int substeps, const PerceivedSequence& reference,
           const EyeSetup& eye, int runs) {
  PerceivedSequence seen;
  double fastest = std::numeric_limits<double>::infinity();
  for (int run = 0; run < runs; ++run) {
    const auto start = Clock::now();
    seen = perceive(shown, eye, substeps);
    fastest = std::min(fastest, seconds_since(start));
  }
  p.eye_seconds_per_frame = fastest / static_cast<double>(shown.size());
  const PerceivedError error = perceived_error(seen, reference, eye);
  p.perceived_psnr_db = error.psnr_db;
  p.visual_difference = error.visual_difference;
}

// Decodes the recorded sequence `repeats` times with a fresh streaming decoder of this configuration, and watches
// the first decoding at the configuration's eye against the reference's. `shown_out`: eye 0's frames, when given.
SweepPoint evaluate(const SweepConfig& config, const Sequence& seq, const EyeSetup& eye, const SweepOptions& options,
                    const std::function<void()>& sequence_done, std::vector<ShownFrame>* shown_out = nullptr) {
  const Recording& rec = seq.rec;
  SweepPoint p;
  p.residual_format = config.decoder.residual.to_string();
  const double levels = std::ldexp(1.0, config.decoder.decoder.output_bits) - 1.0;
  CodeAgreement codes;
  double sum_sq_linear = 0.0;
  std::int64_t linear_samples = 0;
  std::vector<ShownFrame> shown;
  // Decode time of every view in every repeat: the median per view over the repeats, averaged over the views.
  std::vector<std::vector<double>> view_seconds(rec.views.size());
  for (int repeat = 0; repeat < options.repeats; ++repeat) {
    const auto setup_start = Clock::now();
    std::unique_ptr<HeadsetDecoder> decoder;
    try {
      decoder = make_decoder("fixed", config.decoder);  // the hardware model
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
      codes += compare_codes(decoded.drive_codes, view.drive_codes);
      p.linear_max = std::max(p.linear_max, cv::norm(decoded.emitted_linear, view.emitted, cv::NORM_INF));
      sum_sq_linear += cv::norm(decoded.emitted_linear, view.emitted, cv::NORM_L2SQR);
      linear_samples += static_cast<std::int64_t>(view.emitted.total()) * view.emitted.channels();
      p.drive_max_lsb = std::max(p.drive_max_lsb, cv::norm(decoded.drive, view.drive, cv::NORM_INF) * levels);
      if (view.sent.meta.eye == 0) shown.push_back({view.sent.meta.index, decoded.drive_codes});
    }
    p.repeat_seconds_per_frame.push_back(decode_seconds / static_cast<double>(rec.views.size()));
    if (sequence_done) sequence_done();
  }
  p.codes = codes.compared;
  p.differing = codes.differing();
  p.identical_percent = codes.identical_percent();
  p.max_lsb = codes.max_lsb;
  p.mean_lsb = codes.mean_lsb();
  p.rms_lsb = codes.rms_lsb();
  p.linear_rms = std::sqrt(sum_sq_linear / static_cast<double>(linear_samples));
  for (const auto& seconds : view_seconds) {
    p.seconds_per_frame += median(seconds);
    p.min_seconds_per_frame += *std::min_element(seconds.begin(), seconds.end());
  }
  p.seconds_per_frame /= static_cast<double>(view_seconds.size());
  p.min_seconds_per_frame /= static_cast<double>(view_seconds.size());
  if (!seq.reference_seen.pairs.empty() || !seq.reference_seen.xt.empty()) {
    watch(p, shown, config.eye_substeps, seq.reference_seen, eye, 1);
  }
  if (shown_out) *shown_out = std::move(shown);
  return p;
}

}  // namespace

std::string SweepKnob::value_label(int value) const {
  if (value >= 0 && static_cast<std::size_t>(value) < value_names.size()) return value_names[value];
  return std::to_string(value);
}

const std::vector<std::string>& lc_model_names() {
  static const std::vector<std::string> names = {"first", "first+overdrive", "second", "second+overdrive"};
  return names;
}

int lc_model_of(const LcdPanel& lcd) { return (lcd.lc_second_order ? 2 : 0) + (lcd.overdrive ? 1 : 0); }

void set_lc_model(LcdPanel& lcd, int model) {
  const int models = static_cast<int>(lc_model_names().size());
  if (model < 0 || model >= models) {
    throw std::invalid_argument("lc_model " + std::to_string(model) + " is none of the LC models 0.." +
                                std::to_string(models - 1));
  }
  if (model >= 2) {
    if (!lcd.lc_second_order) lcd.lc_second_order = LcSecondOrderParams{};
    lcd.lc_response = LcResponseParams{};  // the panel has one LC model (LcdPanel::validate)
  } else {
    lcd.lc_second_order.reset();
  }
  lcd.overdrive = model % 2 == 1;
}

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
  // The recording keeps every view's codes, drive codes, drive and emitted light beside a pipeline run (twice when
  // the linear-resample-space knobs sweep around their own base).
  const std::int64_t frames = pipeline.frames > 0 ? pipeline.frames : pipeline.default_frames;
  const std::int64_t views = frames * (pipeline.encoder.stereo ? 2 : 1);
  bool two_sequences = false;
  for (const auto& knob : sweep_knobs()) {
    const bool asked = knobs.empty() || std::find(knobs.begin(), knobs.end(), knob.name) != knobs.end();
    two_sequences = two_sequences ||
                    (asked && knob.linear_space_only && pipeline.encoder.resample_space != ResampleSpace::Linear);
  }
  require_memory("for the pipeline and " + std::to_string(views) + " recorded views" +
                     (two_sequences ? " in each of two resample spaces" : ""),
                 run_bytes_per_pixel(pipeline) +
                     kRecordedViewBytesPerPixel * static_cast<double>(views) * (two_sequences ? 2.0 : 1.0),
                 cv::Size(pipeline.width, pipeline.height));
  const std::int64_t points = sweep_point_count(plan_sweep(*this));
  if (shard.count > points) {
    throw std::invalid_argument("--shard " + std::to_string(shard.index) + "/" + std::to_string(shard.count) +
                                ": this sweep has " + std::to_string(points) +
                                " point(s) (the base and every other value of its knobs), so N must be at most " +
                                std::to_string(points));
  }
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

std::vector<SweepPlanKnob> plan_sweep(const SweepOptions& options) {
  const ResampleSpace run_space = options.pipeline.encoder.resample_space;
  SweepConfig base;
  base.decoder = fixed_config_of(options.pipeline);
  PipelineOptions linear_pipeline = options.pipeline;
  linear_pipeline.encoder.resample_space = ResampleSpace::Linear;
  SweepConfig linear_base = base;
  linear_base.decoder = fixed_config_of(linear_pipeline);
  std::vector<SweepPlanKnob> plan;
  for (const auto& knob : sweep_knobs()) {
    const bool asked = options.knobs.empty() ||
                       std::find(options.knobs.begin(), options.knobs.end(), knob.name) != options.knobs.end();
    if (!asked) continue;
    SweepPlanKnob k;
    k.knob = &knob;
    k.default_value = knob.get(base);
    k.resample_space = run_space;
    k.skipped = not_applicable(knob, options.pipeline.panel);
    if (k.skipped.empty()) {
      // A linear-resample-space knob in an encoded-space run sweeps around the same options in linear space.
      k.linear_base = knob.linear_space_only && run_space != ResampleSpace::Linear;
      if (k.linear_base) {
        k.resample_space = ResampleSpace::Linear;
        k.default_value = knob.get(linear_base);
      }
      std::set<int> set(options.values.empty() ? knob.values.begin() : options.values.begin(),
                        options.values.empty() ? knob.values.end() : options.values.end());
      set.insert(k.default_value);
      k.values.assign(set.begin(), set.end());
    }
    plan.push_back(std::move(k));
  }
  return plan;
}

bool sweep_has_linear_base(const std::vector<SweepPlanKnob>& plan) {
  return std::any_of(plan.begin(), plan.end(), [](const SweepPlanKnob& k) { return k.linear_base; });
}

bool sweep_is_point(const SweepPlanKnob& planned, int value) {
  return planned.knob->eye_model || value != planned.default_value;
}

std::int64_t sweep_point_count(const std::vector<SweepPlanKnob>& plan) {
  std::int64_t count = sweep_has_linear_base(plan) ? 2 : 1;  // the base point, and the linear base
  for (const SweepPlanKnob& k : plan) {
    for (int value : k.values) count += sweep_is_point(k, value) ? 1 : 0;
  }
  return count;
}

void finish_sweep(SweepResult& result) {
  const SweepOptions& options = result.options;
  for (SweepKnobResult& kr : result.knobs) {
    if (!kr.skipped.empty()) continue;
    const bool linear = kr.knob->linear_space_only && result.linear_base.has_value();
    const SweepPoint& base = linear ? *result.linear_base : result.base;
    if (kr.knob->eye_model) {
      // The decoder is the base's, with its figures (one shard's base for every part); the eye is the point's own.
      for (SweepPoint& p : kr.points) {
        if (!p.ok()) continue;
        SweepPoint watched = base;
        watched.value = p.value;
        watched.is_default = p.is_default;
        watched.perceived_psnr_db = p.perceived_psnr_db;
        watched.visual_difference = p.visual_difference;
        watched.eye_seconds_per_frame = p.eye_seconds_per_frame;
        p = std::move(watched);
      }
    } else {
      SweepPoint at_base = base;
      at_base.value = kr.default_value;
      at_base.is_default = true;
      kr.points.push_back(std::move(at_base));
    }
    std::sort(kr.points.begin(), kr.points.end(),
              [](const SweepPoint& a, const SweepPoint& b) { return a.value < b.value; });
    for (SweepPoint& p : kr.points) {
      if (!p.ok()) continue;
      p.delta_on_chip_bits = p.on_chip_bits - base.on_chip_bits;
      p.delta_off_chip_bits = p.off_chip_bits - base.off_chip_bits;
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
        throw std::invalid_argument("--values: every value asked for " + kr.knob->name + " was rejected (" +
                                    std::to_string(first_failure->value) + ": " + first_failure->message + ")");
      }
    }
  }
}

SweepResult run_sweep(const SweepOptions& options,
                      const std::function<void(std::int64_t done, std::int64_t total)>& progress) {
  options.validate();
  const Panel& panel = options.pipeline.panel;
  SweepConfig base;
  base.decoder = fixed_config_of(options.pipeline);
  (void)make_decoder("fixed", base.decoder);  // an unusable base configuration fails the whole sweep, with its message
  PipelineOptions linear_pipeline = options.pipeline;
  linear_pipeline.encoder.resample_space = ResampleSpace::Linear;
  SweepConfig linear_base = base;
  linear_base.decoder = fixed_config_of(linear_pipeline);

  SweepResult result;
  result.options = options;
  const std::vector<SweepPlanKnob> plan = plan_sweep(options);
  const SweepShard& shard = options.shard;
  const bool has_linear_base = sweep_has_linear_base(plan);
  const std::int64_t linear_base_number = 1;
  // What this shard evaluates: its points (numbered as SweepShard numbers them), the sequences they decode or watch
  // (every shard that needs a base computes its output, eye points watching it), and the decodes that makes.
  bool needs_encoded = shard.owns(0), needs_linear = has_linear_base && shard.owns(linear_base_number);
  bool any_exact_eye = false, any_lc = false;
  std::int64_t decodes = (shard.owns(0) ? 1 : 0) + (needs_linear ? 1 : 0);
  {
    std::int64_t number = has_linear_base ? linear_base_number : 0;
    for (const SweepPlanKnob& planned : plan) {
      for (int value : planned.values) {
        if (!sweep_is_point(planned, value) || !shard.owns(++number)) continue;
        (planned.linear_base ? needs_linear : needs_encoded) = true;
        if (planned.knob->lc_model) any_lc = true;
        else if (planned.knob->eye_model) any_exact_eye = true;
        else ++decodes;
      }
    }
  }

  const auto start = Clock::now();
  const PursuedTarget target = pursued_target(*options.pipeline.open_source());
  // The encoded sequence is recorded by every shard: its size sets the eye, its hash ties the parts together.
  Sequence encoded{record_reference(options.pipeline), base, {}, {}, {}};
  std::optional<Sequence> linear;
  if (needs_linear) linear = Sequence{record_reference(linear_pipeline), linear_base, {}, {}, {}};
  const int recorded = linear ? 2 : 1;
  result.size = encoded.rec.size;
  result.reduced = encoded.rec.reduced;
  result.views = static_cast<std::int64_t>(encoded.rec.views.size());
  result.reference_seconds_per_frame = encoded.rec.reference_seconds / static_cast<double>(result.views);
  result.recording_hash = recording_hash(encoded.rec);
  if (linear) result.linear_recording_hash = recording_hash(linear->rec);
  const auto eye_of = [&](const Panel& shown_on) {
    return eye_setup(shown_on, options.pipeline.output_bits, options.pipeline.refresh_hz, target.velocity_px_s,
                     target.scan_line, result.size.height);
  };
  const EyeSetup eye = eye_of(panel);
  result.pixels_per_degree = eye.viewer.pixels_per_degree;
  result.target_velocity_deg_s = eye.target_velocity_deg_s;
  result.eye_velocity_deg_s = eye.eye_velocity_deg_s;
  result.scan_line = eye.scan_line;
  const std::int64_t total = result.views * (recorded + decodes * options.repeats);
  std::int64_t done = result.views * recorded;
  const auto sequence_done = [&] {
    done += result.views;
    if (progress) progress(done, total);
  };
  if (progress) progress(done, total);

  // Each needed sequence's base: one untimed decode of the sequence first, so that nothing is timed on cold caches,
  // which also gives the base's shown frames; then its base point, timed, in the shard that owns it.
  SweepOptions once = options;
  once.repeats = 1;
  for (Sequence* seq : {needs_encoded ? &encoded : nullptr, linear ? &*linear : nullptr}) {
    if (!seq) continue;
    seq->reference_seen = perceive(reference_shown(seq->rec), eye, seq->base_config.eye_substeps);
    const SweepPoint warm = evaluate(seq->base_config, *seq, eye, once, {}, &seq->base_shown);
    if (!warm.ok()) throw std::runtime_error(std::string("the base configuration failed: ").append(warm.message));
    const bool owned = seq == &encoded ? shard.owns(0) : shard.owns(linear_base_number);
    if (!owned) continue;
    seq->base = evaluate(seq->base_config, *seq, eye, options, sequence_done);
    seq->base.is_default = true;
    if (!seq->base.ok()) {
      throw std::runtime_error(std::string("the base configuration failed: ").append(seq->base.message));
    }
  }
  if (shard.owns(0)) result.base = encoded.base;
  if (linear && shard.owns(linear_base_number)) result.linear_base = linear->base;
  // The reference decoder's output seen by the exact eye, for the eye-model knobs (made when one is swept here).
  std::optional<PerceivedSequence> exact_seen;
  if (any_exact_eye) exact_seen = perceive(reference_shown(encoded.rec), eye, kExactEyeSubsteps);
  // The LC model's reference: the base decoder's output through the reference LC at the base eye, so that a point
  // differs from it in the LC alone (the decoder's and the eye's own errors are the other knobs').
  std::optional<PerceivedSequence> lc_reference_seen;
  if (any_lc) {
    Panel detailed = panel;
    set_lc_model(detailed.lcd, kLcModelReference);
    lc_reference_seen = perceive(encoded.base_shown, eye_of(detailed), encoded.base_config.eye_substeps);
  }

  std::int64_t number = has_linear_base ? linear_base_number : 0;  // the last base point's
  for (const SweepPlanKnob& planned : plan) {
    const SweepKnob& knob = *planned.knob;
    SweepKnobResult kr;
    kr.knob = &knob;
    kr.default_value = planned.default_value;
    kr.resample_space = planned.resample_space;
    kr.skipped = planned.skipped;
    for (int value : planned.values) {
      if (!sweep_is_point(planned, value) || !shard.owns(++number)) continue;
      const Sequence& seq = planned.linear_base ? *linear : encoded;
      SweepPoint p;
      SweepConfig config = seq.base_config;
      bool set = true;
      try {
        knob.set(config, value);
      } catch (const std::invalid_argument& e) {
        p.status = "rejected";
        p.message = e.what();
        set = false;
      }
      if (knob.eye_model) {
        // The decoder is the base's (finish_sweep() gives the point its figures); the eye (or its LC) is the
        // knob's, held to the exact eye (or the reference LC).
        if (set && knob.lc_model) {
          watch(p, seq.base_shown, config.eye_substeps, *lc_reference_seen, eye_of(config.decoder.decoder.panel),
                options.repeats);
        } else if (set) {
          watch(p, seq.base_shown, config.eye_substeps, *exact_seen, eye, options.repeats);
        }
        p.is_default = value == kr.default_value;
      } else {
        if (set) p = evaluate(config, seq, eye, options, sequence_done);
        if (!p.ok()) {
          done += result.views * options.repeats -
                  static_cast<std::int64_t>(p.repeat_seconds_per_frame.size()) * result.views;
          if (progress) progress(done, total);
        }
        p.is_default = false;
      }
      p.value = value;
      kr.points.push_back(std::move(p));
    }
    result.knobs.push_back(std::move(kr));
  }
  result.wall_seconds = seconds_since(start);
  if (shard.whole()) finish_sweep(result);
  return result;
}

}  // namespace trm::cli
