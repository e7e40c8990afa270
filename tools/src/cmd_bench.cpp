// `trm bench`: decode throughput of the streaming and frame fixed-point decoders, the double reference and an OpenCV
// float32 decoder of the same per-pair math (bench/opencv_pipeline), in one process, repeats interleaved, on the same
// encoded views at headset sizes, beside the resource report's memory (issue 13).
#include "commands.hpp"
#include "elapsed.hpp"
#include "hw_report.hpp"
#include "sweep.hpp"

#include "opencv_trm.hpp"

#include "trm/atomic_file.hpp"
#include "trm/decoder.hpp"
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/metrics.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/scene.hpp"

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

namespace trm::cli {

namespace {

constexpr double kMiB = 1024.0 * 1024.0;
constexpr double kRates[] = {90.0, 120.0, 144.0};
// The drive codes alone, as `trm feed` runs the decoder: no motion test where its w goes unused.
constexpr bool kFixedMotionWeightStatistics = false;

struct BenchSize {
  int width;
  int height;
  bool stereo;
  std::string label() const {
    return std::to_string(width) + "x" + std::to_string(height) + (stereo ? " x2 stereo" : "");
  }
};

struct BenchOptions {
  bool quick = false;
  int repeats = 0;  // 0: 3, or 2 with --quick
  int pairs = 0;    // frame pairs per repeat; 0: 2, or 1 with --quick
  std::string scene = "panorama";
  std::string json;
  std::vector<std::string> sizes;   // WxH or WxHs (stereo); empty: the headset sizes
  std::vector<std::string> panels;  // empty: vive and lcd
  int threads = 0;                  // the streaming decoder's threads; 0: the machine's hardware threads
  std::vector<std::string> only;    // contenders to time besides the OpenCV yardstick; empty: all
  std::vector<std::string> formats;  // KNOB=VALUE: a format set of the fixed-point decoders (trm sweep's knobs)
  bool no_skip = false;  // FixedDecoderConfig::skip_unneeded = false: the rate where the content lets nothing skip
};

// A fixed-point format set from --format KNOB=VALUE, by `trm sweep`'s knobs (one home for their names and for how
// each sets the configuration), applied in order onto `config`. Throws std::invalid_argument naming the bad entry:
// not KNOB=VALUE, an unknown knob (the known ones listed), an eye-model knob, a knob of the linear resample space
// (the bench decodes in the encoded space), a value that is not a whole number, or a configuration the decoder
// rejects (its stage and rule).
void apply_formats(FixedDecoderConfig& config, const std::vector<std::string>& formats) {
  for (const std::string& entry : formats) {
    const std::size_t equals = entry.find('=');
    const std::string name = entry.substr(0, equals);
    const SweepKnob* knob = find_sweep_knob(name);
    if (equals == std::string::npos || knob == nullptr || knob->eye_model || knob->linear_space_only) {
      std::string known;
      for (const SweepKnob& k : sweep_knobs()) {
        if (!k.eye_model && !k.linear_space_only) known.append(known.empty() ? "" : ", ").append(k.name);
      }
      const std::string why = equals == std::string::npos ? "expected KNOB=VALUE"
                              : knob == nullptr           ? "unknown knob '" + name + "'"
                              : knob->eye_model           ? "'" + name + "' is a knob of the eye model, not of the decoder"
                                                          : "'" + name + "' is a knob of the linear resample space; trm "
                                                            "bench decodes in the encoded space";
      throw std::invalid_argument("--format '" + entry + "': " + why + "; knobs: " + known);
    }
    const std::string text = entry.substr(equals + 1);
    int value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
      throw std::invalid_argument("--format '" + entry + "': the value must be a whole number");
    }
    SweepConfig sweep_config{config};
    try {
      knob->set(sweep_config, value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--format '" + entry + "': " + e.what());
    }
    config = sweep_config.decoder;
  }
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--format: ") + e.what());
  }
}

std::string formats_label(const std::vector<std::string>& formats) {
  std::string label;
  for (const std::string& f : formats) label.append(label.empty() ? "" : " ").append(f);
  return label.empty() ? "default formats" : label;
}

// Every contender's name, in the order they are listed; the OpenCV decoder is the yardstick of every ratio and is
// always timed.
const std::vector<std::string> kContenders = {"fixed",     "fixed-1t",         "fixed+planes",  "fixed-frame",
                                              "reference", "reference+planes", "opencv-float32"};

BenchSize parse_bench_size(const std::string& text) {
  const bool stereo = !text.empty() && text.back() == 's';
  const std::string dims = stereo ? text.substr(0, text.size() - 1) : text;
  const std::size_t x = dims.find('x');
  int width = 0;
  int height = 0;
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    std::size_t used_w = 0;
    std::size_t used_h = 0;
    width = std::stoi(dims.substr(0, x), &used_w);
    height = std::stoi(dims.substr(x + 1), &used_h);
    if (used_w != x || used_h != dims.size() - x - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw std::invalid_argument("--size '" + text + "': expected WxH, or WxHs for a stereo pair of WxH views");
  }
  if (width < 2 || height < 2 || width > 8192 || height > 8192) {
    throw std::invalid_argument("--size '" + text + "': each side must be in [2, 8192]");
  }
  return {width, height, stereo};
}

// A field of /proc/self/status in kB (VmRSS, VmHWM); 0 where it cannot be read.
double status_kib(const std::string& field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  }
  return 0.0;
}

// Starts a new peak of the resident set (Linux: "5" into clear_refs resets VmHWM to VmRSS); false where it cannot,
// and then the peak is the process's own (getrusage).
bool reset_peak() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

double peak_mib() {
  const double hwm = status_kib("VmHWM");
  if (hwm > 0.0) return hwm / 1024.0;
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// CPU time of the whole process (user + system, every thread).
double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// One contender: a fresh decoder per repeat (built outside the timing), decoding every view in order.
struct Contender {
  std::string name;
  int threads = 1;
  std::function<std::function<void(const LinkFrame&)>()> make;
  std::vector<double> seconds;      // per repeat
  std::vector<double> first_pair_seconds;  // per repeat: the fresh decoder's first pair, timed apart before `seconds`
  std::vector<double> cpu_seconds;  // per repeat, every thread of the process (steadier than wall time on a loaded
                                    // machine; the machine's other processes are not in it)
  double peak_rss_mib = 0.0;
  double rss_before_mib = 0.0;
  // A fixed-point decoder's FixedDecoderConfig::motion_weight_statistics (the JSON's null for the others).
  std::optional<bool> motion_weight_statistics;
};

FixedDecoderConfig config_for(const BenchSize& size, const std::string& panel, const std::vector<std::string>& formats) {
  FixedDecoderConfig config;
  config.decoder.link.reduction = 0.5;
  config.decoder.link.stereo = size.stereo;
  config.decoder.panel = parse_panel(panel);
  apply_formats(config, formats);
  return config;
}

// DESIGN §6 at the bench's formats on the bench's views: the streaming decoder's drive codes against the reference's.
// An LCD reference adopts the fixed decoder's codes as its panel history after every view (the synchronised
// comparison the criterion is judged on: README "Accuracy").
Json reference_agreement(const FixedDecoderConfig& config, const std::vector<LinkFrame>& views, std::ostream& text) {
  FixedDecoderConfig codes_only = config;  // as the `fixed` contender runs
  codes_only.decoder.report_planes = false;
  codes_only.motion_weight_statistics = kFixedMotionWeightStatistics;
  const std::unique_ptr<HeadsetDecoder> fixed = make_decoder("fixed", codes_only);
  const std::unique_ptr<HeadsetDecoder> reference = make_decoder("reference", codes_only);
  auto* const synchronised = dynamic_cast<ReferenceDecoder*>(reference.get());
  const bool lcd = config.decoder.panel.has_history();
  CodeAgreement codes;
  for (const LinkFrame& view : views) {
    const DecodedFrame decoded = fixed->decode(view);
    codes += compare_codes(decoded.drive_codes, reference->decode(view).drive_codes);
    if (lcd && synchronised != nullptr) synchronised->adopt_panel_history(decoded);
  }
  const bool met = kReferenceAgreementCriterion.met_by(codes);
  text << "  DESIGN §6, fixed against the reference" << (lcd ? " (synchronised)" : "") << ": " << std::setprecision(4)
       << codes.identical_percent() << " % of " << codes.compared << " codes identical, max " << std::setprecision(0)
       << codes.max_lsb << " LSB: " << (met ? "met" : "NOT met") << " (>= "
       << std::setprecision(1) << kReferenceAgreementCriterion.min_identical_percent() << " %, max "
       << std::setprecision(0) << kReferenceAgreementCriterion.max_lsb << " LSB)\n";
  return {{"codes", codes.compared},
          {"identical_percent", codes.identical_percent()},
          {"max_lsb", codes.max_lsb},
          {"lcd_synchronised", lcd},
          {"meets_design_6", met}};
}

std::vector<LinkFrame> encode_views(const BenchSize& size, const BenchOptions& options,
                                    const EncoderConfig& link) {
  SceneParams params;
  params.width = size.width;
  params.height = size.height;
  params.supersample = 1;
  const auto scene = make_scene(options.scene, params);
  const TrmEncoder encoder(link);
  std::vector<LinkFrame> views;
  const int frames = 2 * options.pairs;
  for (int t = 0; t < frames; ++t) {
    const cv::Mat linear = scene->linear_frame(t);
    for (int eye = 0; eye < (size.stereo ? 2 : 1); ++eye) views.push_back(encoder.encode(linear, t, eye));
  }
  return views;
}

Json hardware_memory(const FixedDecoderConfig& config, const BenchSize& size) {
  const FixedStreamingDecoder decoder(config);
  const Json hw = hardware_json(decoder.report(cv::Size(size.width, size.height)));
  const Json& totals = hw["totals"];
  const int eyes = size.stereo ? 2 : 1;
  const double on_chip = eyes * static_cast<double>(totals["on_chip_bits"].get<std::int64_t>()) / 8.0 / kMiB;
  const double off_chip = eyes * static_cast<double>(totals["off_chip_bits"].get<std::int64_t>()) / 8.0 / kMiB;
  const double output = eyes * 3.0 * size.width * size.height * config.decoder.output_bits / 8.0 / kMiB;
  return {{"on_chip_mib", on_chip}, {"off_chip_mib", off_chip}, {"output_frame_mib", output},
          {"total_mib", on_chip + off_chip + output}};
}

Json bench_one(const BenchSize& size, const std::string& panel, const BenchOptions& options, std::ostream& text) {
  FixedDecoderConfig config = config_for(size, panel, options.formats);
  config.skip_unneeded = !options.no_skip;
  const std::vector<LinkFrame> views = encode_views(size, options, config.decoder.link);
  std::vector<Contender> contenders;
  // The hardware model's output is the drive codes: the streaming decoder without the report planes, on the
  // machine's threads and on one; then as `trm run` uses it (one thread, report planes) and the frame schedule, which
  // return the planes. The codes alone need no motion weight statistics either. The reference as the agreement check
  // and a comparison of codes run it (drive codes, as the OpenCV decoder returns), and as `trm run` does (planes).
  FixedDecoderConfig codes_only = config;
  codes_only.decoder.report_planes = false;
  codes_only.motion_weight_statistics = kFixedMotionWeightStatistics;
  FixedDecoderConfig banded = codes_only;
  banded.threads = options.threads;
  const auto asked_for = [&options](const std::string& name) {
    return std::find(options.only.begin(), options.only.end(), name) != options.only.end();
  };
  // On one thread the banded decoder is the one-thread decoder: it is timed once, as "fixed", and --only fixed-1t
  // selects it too.
  const auto wanted = [&options, &asked_for, &banded](const std::string& name) {
    return options.only.empty() || asked_for(name) || (name == "fixed" && banded.threads <= 1 && asked_for("fixed-1t"));
  };
  const auto add = [&contenders, &size, &wanted](std::string name, const char* impl, FixedDecoderConfig c) {
    if (!wanted(name)) return;
    // The reference splits its stages' rows over OpenCV's threads; the fixed-point frame decoder runs on one.
    const int threads = std::string(impl) == "fixed"       ? FixedStreamingDecoder(c).threads_for(cv::Size(size.width, size.height))
                        : std::string(impl) == "reference" ? cv::getNumThreads()
                                                           : 1;
    contenders.push_back({std::move(name), threads,
                          [impl, c] {
                            std::shared_ptr<HeadsetDecoder> d = make_decoder(impl, c);
                            return std::function<void(const LinkFrame&)>([d](const LinkFrame& f) { d->decode(f); });
                          },
                          {}, {}, {}, 0.0, 0.0,
                          std::string(impl) == "reference" ? std::nullopt
                                                           : std::optional<bool>(c.motion_weight_statistics)});
  };
  if (banded.threads > 1) add("fixed", "fixed", banded);
  add(banded.threads > 1 ? "fixed-1t" : "fixed", "fixed", codes_only);
  add("fixed+planes", "fixed", config);
  add("fixed-frame", "fixed-frame", config);
  add("reference", "reference", codes_only);
  add("reference+planes", "reference", config);
  contenders.push_back({"opencv-float32", cv::getNumThreads(),
                        [&config] {
                          auto d = std::make_shared<bench::OpencvTrmDecoder>(config.decoder);
                          return std::function<void(const LinkFrame&)>([d](const LinkFrame& f) { d->decode(f); });
                        },
                        {}, {}, {}, 0.0, 0.0, std::nullopt});
  const int repeats = options.repeats;
  // The views of the first frame pair (both eyes of each link frame).
  const std::size_t first_pair_views = std::min(views.size(), std::size_t{size.stereo ? 4u : 2u});
  for (int repeat = 0; repeat < repeats; ++repeat) {
    // Interleaved, the order rotating per repeat, so that no contender always runs first (cold) or last.
    for (std::size_t k = 0; k < contenders.size(); ++k) {
      Contender& c = contenders[(k + static_cast<std::size_t>(repeat)) % contenders.size()];
      const bool measure_memory = repeat == 0;
      if (measure_memory) {
        // The heap's free pages back to the system first, so that what the decoder takes shows in the peak and is
        // not hidden in memory an earlier contender freed; the decoder is built inside the measurement.
        malloc_trim(0);
        c.rss_before_mib = status_kib("VmRSS") / 1024.0;
        reset_peak();
      }
      auto decode = c.make();
      // The steady state a headset runs in: a fresh decoder's first pair builds its geometry and touches its frame
      // stores and output for the first time (page faults), so it is timed apart and then every view is timed.
      const auto warm0 = std::chrono::steady_clock::now();
      for (std::size_t v = 0; v < first_pair_views; ++v) decode(views[v]);
      c.first_pair_seconds.push_back(seconds_since(warm0));
      const double cpu0 = process_cpu_seconds();
      const auto t0 = std::chrono::steady_clock::now();
      for (const LinkFrame& view : views) decode(view);
      c.seconds.push_back(seconds_since(t0));
      c.cpu_seconds.push_back(process_cpu_seconds() - cpu0);
      if (measure_memory) c.peak_rss_mib = peak_mib();
    }
  }
  const double link_frames = static_cast<double>(views.size()) / (size.stereo ? 2.0 : 1.0);
  const double frame_pixels = static_cast<double>(size.width) * size.height * (size.stereo ? 2.0 : 1.0);
  const double opencv_seconds = median(contenders.back().seconds);
  Json result = {{"size", {size.width, size.height}},
                 {"stereo", size.stereo},
                 {"panel", panel},
                 {"link_frames", link_frames},
                 {"output_mpix_per_frame", frame_pixels / 1e6},
                 {"hw_report_memory", hardware_memory(config, size)}};
  text << "\n" << size.label() << ", " << panel << ", r = 0.5, " << options.scene << ", "
       << static_cast<int>(link_frames) << " frames, median of " << repeats << ", " << formats_label(options.formats)
       << (options.no_skip ? ", no skips" : "")
       << "\n";
  text << "  " << std::left << std::setw(16) << "decoder" << std::right << std::setw(9) << "Mpix/s" << std::setw(11)
       << "ms/frame" << std::setw(10) << "vs cv" << std::setw(9) << "RT@90" << std::setw(9) << "RT@120"
       << std::setw(9) << "RT@144" << std::setw(9) << "threads" << std::setw(11) << "peak MiB" << std::setw(11) << "work MiB" << std::setw(13) << "cpu ms/frame" << std::setw(15) << "1st pair ms" << "\n";
  const double hw_total_mib = result["hw_report_memory"]["total_mib"].get<double>();
  Json decoders = Json::array();
  for (const Contender& c : contenders) {
    const double seconds = median(c.seconds);
    const double mpix_per_s = frame_pixels * link_frames / seconds / 1e6;
    const double ms_per_frame = 1e3 * seconds / link_frames;
    // What the decoder added to the resident set at its peak: its tables, frame stores, line buffers and output.
    const double working_mib = std::max(0.0, c.peak_rss_mib - c.rss_before_mib);
    Json realtime = Json::object();
    for (double hz : kRates) realtime[std::to_string(static_cast<int>(hz))] = mpix_per_s * 1e6 / (frame_pixels * hz);
    decoders.push_back({{"name", c.name},
                        {"threads", c.threads},
                        {"motion_weight_statistics", c.motion_weight_statistics ? Json(*c.motion_weight_statistics)
                                                                                : Json(nullptr)},
                        {"mpix_per_s", mpix_per_s},
                        {"ms_per_frame", ms_per_frame},
                        {"cpu_ms_per_frame", 1e3 * median(c.cpu_seconds) / link_frames},
                        {"repeat_cpu_seconds", c.cpu_seconds},
                        {"ratio_to_opencv", opencv_seconds / seconds},
                        {"realtime_factor", realtime},
                        {"peak_rss_mib", c.peak_rss_mib},
                        {"rss_before_mib", c.rss_before_mib},
                        {"working_mib", working_mib},
                        {"working_over_hw_report", working_mib / hw_total_mib},
                        {"repeat_seconds", c.seconds},
                        {"first_pair_ms", 1e3 * median(c.first_pair_seconds)},
                        {"repeat_first_pair_seconds", c.first_pair_seconds}});
    text << "  " << std::left << std::setw(16) << c.name << std::right << std::fixed << std::setprecision(2)
         << std::setw(9) << mpix_per_s << std::setw(11) << ms_per_frame << std::setw(10) << opencv_seconds / seconds
         << std::setprecision(3) << std::setw(9) << realtime["90"].get<double>() << std::setw(9)
         << realtime["120"].get<double>() << std::setw(9) << realtime["144"].get<double>() << std::setw(9)
         << c.threads << std::setprecision(1) << std::setw(11) << c.peak_rss_mib << std::setw(11) << working_mib
         << std::setprecision(2) << std::setw(13)
         << 1e3 * median(c.cpu_seconds) / link_frames << std::setprecision(1) << std::setw(15)
         << 1e3 * median(c.first_pair_seconds) << "\n";
  }
  const Json& hw = result["hw_report_memory"];
  text << "  hw-report memory: " << std::fixed << std::setprecision(1) << hw["on_chip_mib"].get<double>()
       << " MiB on chip + " << hw["off_chip_mib"].get<double>() << " MiB off chip + "
       << hw["output_frame_mib"].get<double>() << " MiB output drive codes = " << hw["total_mib"].get<double>()
       << " MiB (peak RSS includes the process and the encoded views; work = peak less the resident set before the "
          "decoder was built, after the heap's free pages went back; fixed+planes, fixed-frame and reference+planes "
          "also return three double planes per view)\n";
  result["decoders"] = std::move(decoders);
  result["reference_agreement"] = reference_agreement(config, views, text);
  return result;
}

}  // namespace

void register_bench(CLI::App& app, Action& action) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Time the fixed-point decoders (streaming, frame), the double reference and an OpenCV float32 "
               "decoder of the same math at headset sizes, r = 1/2, OLED and LCD");
  cmd->add_flag("--quick", options->quick, "Small and fast (CI): 96x64 stereo and 128x96, 1 pair, 2 repeats");
  cmd->add_option("--repeats", options->repeats, "Timed repeats per contender, interleaved (default 3)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--pairs", options->pairs, "Frame pairs decoded per repeat (default 2)")->check(CLI::Range(1, 1000));
  cmd->add_option("--scene", options->scene, "Scene to encode")->capture_default_str();
  cmd->add_flag("--no-skip", options->no_skip,
                "Fixed-point decoders: run every step where the content would let one skip (static lines, residual "
                "zero lines and runs): the rate no scene goes below; the codes are the same");
  cmd->add_option("--json", options->json, "Also write the figures as JSON to FILE");
  cmd->add_option("--size", options->sizes,
                  "View size WxH, or WxHs for a stereo pair (repeatable; default 1080x1200s 2160x1200 2880x1600)");
  cmd->add_option("--panel", options->panels, "Panel (repeatable; default vive and lcd)");
  cmd->add_option("--threads", options->threads,
                  "Threads of the streaming decoder (bands of output lines; default: the machine's hardware threads)")
      ->check(CLI::Range(1, kMaxDecoderThreads));
  cmd->add_option("--format", options->formats,
                  "A format of the fixed-point decoders, KNOB=VALUE with trm sweep's knobs (repeatable, e.g. "
                  "--format linear_frac_bits=20 --format bilinear_weight_frac_bits=8); the run also checks DESIGN §6 "
                  "against the reference at these formats");
  cmd->add_option("--only", options->only,
                  "Time only these contenders (repeatable) besides opencv-float32, the yardstick of every ratio")
      ->check(CLI::IsMember(kContenders));
  cmd->callback([options, &action] {
    action = [options] {
      BenchOptions o = *options;
      if (o.repeats == 0) o.repeats = o.quick ? 2 : 3;
      if (o.pairs == 0) o.pairs = o.quick ? 1 : 2;
      if (o.threads == 0) {
        o.threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxDecoderThreads);
      }
      if (!o.json.empty()) io::check_file_target(o.json);
      std::vector<BenchSize> sizes = o.quick ? std::vector<BenchSize>{{96, 64, true}, {128, 96, false}}
                                             : std::vector<BenchSize>{{1080, 1200, true}, {2160, 1200, false},
                                                                      {2880, 1600, false}};
      if (!o.sizes.empty()) {
        sizes.clear();
        for (const std::string& text : o.sizes) sizes.push_back(parse_bench_size(text));
      }
      const std::vector<std::string> panels =
          o.panels.empty() ? std::vector<std::string>{"vive", "lcd"} : o.panels;
      for (const std::string& panel : panels) {  // rejected before any work
        config_for(sizes.front(), panel, o.formats);
      }
      double load[3] = {0.0, 0.0, 0.0};
      if (getloadavg(load, 3) != 3) load[0] = load[1] = load[2] = 0.0;
      Json report = {{"machine", {{"hardware_threads", std::thread::hardware_concurrency()},
                                  {"load_average_at_start", {load[0], load[1], load[2]}}}},
                     {"parameters", {{"reduction", 0.5}, {"scene", o.scene}, {"pairs", o.pairs},
                                     {"repeats", o.repeats}, {"quick", o.quick}, {"formats", o.formats},
                                     {"skip_unneeded", !o.no_skip}}}};
      Json results = Json::array();
      std::cout << "trm bench: " << std::thread::hardware_concurrency() << " hardware threads, load average "
                << load[0] << " at start; OpenCV threads " << cv::getNumThreads() << "\n";
      for (const BenchSize& size : sizes) {
        for (const std::string& panel : panels) results.push_back(bench_one(size, panel, o, std::cout));
      }
      report["results"] = std::move(results);
      if (!o.json.empty()) io::write_file_atomically(o.json, report.dump(2) + "\n");
      return 0;
    };
  });
}

}  // namespace trm::cli
