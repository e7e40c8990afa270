#include "compare.hpp"

#include "pipeline.hpp"

#include "trm/encoder_json.hpp"
#include "trm/metrics.hpp"
#include "trm/mtcd.hpp"
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

// Luma alternation over a pair, |Y_a - Y_b| / (Y_a + Y_b) per pixel (0 where both are black), summed.
double alternation_contrast_sum(const cv::Mat& luma_a, const cv::Mat& luma_b) {
  double sum = 0.0;
  for (int y = 0; y < luma_a.rows; ++y) {
    const auto* a = luma_a.ptr<double>(y);
    const auto* b = luma_b.ptr<double>(y);
    for (int x = 0; x < luma_a.cols; ++x) {
      const double total = a[x] + b[x];
      if (total > 0.0) sum += std::abs(a[x] - b[x]) / total;
    }
  }
  return sum;
}

// Kim et al.'s MTCD is defined on display colour values: the 8-bit sRGB encoding of the light.
cv::Mat display_values(const cv::Mat& linear) { return to_encoded(linear, Transfer::Srgb) * 255.0; }

// The running figures of one method's run, per view in slot order.
class MethodMeter {
 public:
  explicit MethodMeter(const Panel& panel, int output_bits) : panel_(panel), output_bits_(output_bits), pairs_(panel) {}

  void add(const DecodedView& view) {
    const DecodedFrame& shown = *view.decoded;
    const FrameMeta& slot = view.slot;
    const double full_pixels = static_cast<double>(slot.full_width) * slot.full_height;
    ++views_;
    full_pixels_ += full_pixels;
    pixels_rendered_ += static_cast<double>(view.pixels_rendered);
    pixels_sent_ += view.sent ? static_cast<double>(view.sent->codes.total()) : 0.0;

    const cv::Mat reference = full_rate_emission(*view.linear_full, panel_, output_bits_);
    const cv::Mat luma_emitted = luma(shown.emitted_linear);
    const cv::Mat luma_reference = luma(reference);
    luma_sum_ += cv::sum(luma_emitted)[0];
    reference_luma_sum_ += cv::sum(luma_reference)[0];

    Eye& eye = eyes_[slot.eye];
    if (eye.t == slot.index - 1) {
      mtcd_sum_ += mtcd({eye.display, display_values(shown.emitted_linear)});
      reference_mtcd_sum_ += mtcd({eye.reference_display, display_values(reference)});
      ++mtcd_steps_;
      if (slot.index % 2 == 1) {
        flicker_sum_ += alternation_contrast_sum(eye.luma, luma_emitted);
        reference_flicker_sum_ += alternation_contrast_sum(eye.reference_luma, luma_reference);
        flicker_samples_ += static_cast<double>(luma_emitted.total());
      }
    }
    if (const auto pair = pairs_.add(slot.eye, slot.index, shown.emitted_linear, reference)) {
      const double psnr = psnr_srgb(pair->perceived, pair->reference);
      ++pair_count_;
      if (std::isfinite(psnr)) {
        psnr_sum_ += psnr;
        ++finite_pairs_;
      }
    }
    eye.t = slot.index;
    eye.luma = luma_emitted;
    eye.reference_luma = luma_reference;
    eye.display = display_values(shown.emitted_linear);
    eye.reference_display = display_values(reference);
  }

  void finish(MethodMeasure& m) const {
    m.views = views_;
    m.pixels_rendered_saved_percent = full_pixels_ > 0 ? 100.0 * (1.0 - pixels_rendered_ / full_pixels_) : 0.0;
    m.pixels_sent_saved_percent = full_pixels_ > 0 ? 100.0 * (1.0 - pixels_sent_ / full_pixels_) : 0.0;
    m.luminance_percent = reference_luma_sum_ > 0 ? 100.0 * luma_sum_ / reference_luma_sum_ : 0.0;
    m.flicker_contrast = flicker_samples_ > 0 ? flicker_sum_ / flicker_samples_ : 0.0;
    m.reference_flicker_contrast = flicker_samples_ > 0 ? reference_flicker_sum_ / flicker_samples_ : 0.0;
    m.mtcd = mtcd_steps_ > 0 ? mtcd_sum_ / mtcd_steps_ : 0.0;
    m.reference_mtcd = mtcd_steps_ > 0 ? reference_mtcd_sum_ / mtcd_steps_ : 0.0;
    m.pairs = pair_count_;
    // Every pair exact: +inf, as psnr_srgb says of one exact pair.
    m.mean_pair_psnr_db = finite_pairs_ > 0 ? psnr_sum_ / static_cast<double>(finite_pairs_)
                                           : (pair_count_ > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  }

 private:
  struct Eye {
    std::int64_t t = -2;
    cv::Mat luma, reference_luma, display, reference_display;
  };
  const Panel& panel_;
  int output_bits_;
  PairTracker pairs_;
  std::map<int, Eye> eyes_;
  std::int64_t views_ = 0;
  double full_pixels_ = 0, pixels_rendered_ = 0, pixels_sent_ = 0;
  double luma_sum_ = 0, reference_luma_sum_ = 0;
  double flicker_sum_ = 0, reference_flicker_sum_ = 0, flicker_samples_ = 0;
  double mtcd_sum_ = 0, reference_mtcd_sum_ = 0;
  std::int64_t mtcd_steps_ = 0;
  double psnr_sum_ = 0;
  std::int64_t pair_count_ = 0, finite_pairs_ = 0;
};

std::string number(double v, int digits) {
  if (std::isinf(v)) return "exact";
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
      {"MTCD", [](const MethodMeasure& m) { return number(m.mtcd, 3); }},
      {"MTCD (full rate)", [](const MethodMeasure& m) { return number(m.reference_mtcd, 3); }},
      {"pair PSNR dB", [](const MethodMeasure& m) { return number(m.mean_pair_psnr_db, 2); }},
  };
  return all;
}

}  // namespace

std::vector<std::string> CompareOptions::chosen_methods() const {
  if (!methods.empty()) return methods;
  std::vector<std::string> all;
  for (const DisplayMethod& m : display_methods()) all.push_back(m.name);
  return all;
}

void CompareOptions::validate() const {
  pipeline.validate();
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
  const std::int64_t total =
      static_cast<std::int64_t>(methods.size()) * frames * (options.pipeline.encoder.stereo ? 2 : 1);
  std::int64_t done = 0;
  for (const std::string& spec : methods) {
    PipelineOptions run = options.pipeline;
    run.method = spec;
    // Every method is judged in linear light (DESIGN §9): the double-precision headset side for all of them.
    run.impl = "reference";
    run.impl_given = false;
    run.compare_reference = false;
    if (run.link_preset.empty()) run.link_preset = "dp1.4";  // bandwidth per link frame for every method
    MethodMeter meter(run.panel, run.output_bits);
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
    measure.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    meter.finish(measure);
    measure.mean_link_payload_bits = link_frames > 0 ? payload_sum / static_cast<double>(link_frames) : 0.0;
    if (outcome.link) {
      measure.peak_link_wire_bits = outcome.link->summary.peak_wire_bits;
      measure.link_fits = outcome.link->summary.fits;
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
      << "frames; flicker and pair PSNR at a fixed gaze (Talbot-Plateau).\n\n|";
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
         "reference_mtcd,pairs,mean_pair_psnr_db,seconds\n";
  out.precision(10);
  for (const MethodMeasure& m : result.methods) {
    out << m.method << ',' << m.views << ',' << m.pixels_rendered_saved_percent << ',' << m.pixels_sent_saved_percent
        << ',' << m.mean_link_payload_bits << ',' << m.peak_link_wire_bits << ',' << (m.link_fits ? 1 : 0) << ','
        << m.luminance_percent << ',' << m.flicker_contrast << ',' << m.reference_flicker_contrast << ',' << m.mtcd
        << ',' << m.reference_mtcd << ',' << m.pairs << ','
        << (std::isinf(m.mean_pair_psnr_db) ? std::string("inf") : number(m.mean_pair_psnr_db, 6)) << ','
        << m.seconds << '\n';
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
                     {"encoder", encoder_json(p.encoder)},
                     {"output_bits", p.output_bits},
                     {"sensitivity", p.sensitivity},
                     {"panel", p.panel},
                     {"link", p.link_preset.empty() ? "dp1.4" : p.link_preset},
                     {"seed", p.seed}};
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
                       {"seconds", m.seconds}});
  }
  j["methods"] = methods;
  return j;
}

}  // namespace trm::cli
