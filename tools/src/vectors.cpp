#include "vectors.hpp"

#include "hw_report.hpp"

#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"

#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

std::uint64_t fnv1a64(const std::string& bytes) {
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

namespace {

int hex_digits(int bits) { return (bits + 3) / 4; }

// One line of hex words per image line; signed values in two's complement over the word's hex digits.
std::string plane_text(const FixedStagePlane& p) {
  const int digits = hex_digits(p.bits);
  const std::uint64_t mask = digits >= 16 ? ~std::uint64_t{0} : (std::uint64_t{1} << (4 * digits)) - 1;
  const std::size_t per_line = static_cast<std::size_t>(p.size.width) * static_cast<std::size_t>(p.channels);
  std::string out;
  out.reserve(p.values.size() * static_cast<std::size_t>(digits + 1));
  char word[24];
  for (std::size_t i = 0; i < p.values.size(); ++i) {
    std::snprintf(word, sizeof word, "%0*llx", digits,
                  static_cast<unsigned long long>(static_cast<std::uint64_t>(p.values[i]) & mask));
    out += word;
    out += (i + 1) % per_line == 0 ? '\n' : ' ';
  }
  return out;
}

std::string readme_text(const PipelineOptions& options, const FixedDecoderConfig& config,
                        const std::map<std::string, FixedStagePlane>& stages, const std::vector<std::string>& order) {
  std::ostringstream s;
  s << "# Golden vectors of the fixed-point TRM decoder\n\n"
    << "Scene `" << options.scene << "`, " << options.width << "x" << options.height << ", r = "
    << options.encoder.reduction << ", " << options.encoder.bits << "-bit link, panel `" << options.panel.name << "`, "
    << options.output_bits << "-bit drive, s = " << options.sensitivity << ", residual "
    << config.residual.to_string() << ", D and U in the " << to_string(options.encoder.resample_space)
    << " resample space.\n"
    << "Produced by the frame-at-a-time fixed-point decoder (bit-identical to the streaming one).\n\n"
    << "## Format\n\n"
    << "* One file per frame and stage: `frame_NNN_<full|reduced>_<stage>.hex` (`frame_NNN_eyeE_...` in stereo).\n"
    << "* One line per image line, top to bottom; words separated by one space, left to right; three channels per\n"
    << "  pixel interleaved R G B (the motion contrast `c` and weight `w` have one word per pixel).\n"
    << "* Each word is the stage's raw integer in lower-case hex, zero-padded to the format width rounded up to\n"
    << "  whole hex digits; signed stages are two's complement over those digits (sign-extended).\n"
    << "* Value = raw / 2^f for a Q format with f fraction bits (uQi.f unsigned, sQi.f signed, i includes the sign).\n"
    << "* `report.json` lists every file with its 64-bit FNV-1a hash (the form checked in under tests/golden/).\n\n"
    << "## Stages\n\n"
    << "| stage | frames | Q format | bits | hex digits | size | what |\n|---|---|---|---|---|---|---|\n";
  std::map<std::string, std::string> what = {
      {"codes", "received link codes E_t (full frames) or i (reduced frames)"},
      {"I", "I = lin(E_t), the code ROM"},
      {"d", "d_t = Q_b(D(E_t)), reduced size, as the frame store holds it (link codes, exact half-code ties rounded up)"},
      {"L", "L = lin(U(d_t)), the EOTF LUT after the bilinear U"},
      {"beta", "beta = 2 I - L (Eq. 2)"},
      {"shown", "clamp(beta, 0, 1)"},
      {"rho", "rho = beta - shown (plus any LCD shortfall) in the residual store format"},
      {"alpha", "alpha = lin(U(i)) (Eq. 1)"},
      {"L_prev", "L_{t-1} = lin(U(d_{t-1})) for the motion test"},
      {"c", "motion contrast abs(Y(L_{t-1}) - Y(alpha)) / (Y(L_{t-1}) + Y(alpha)) (Eq. 5), one per pixel"},
      {"w", "w = exp(-s c) (Eq. 6), one per pixel"},
      {"alpha_prime", "alpha' = clamp(alpha + w rho, 0, 1) (Eq. 4); clamp(alpha) without a residual"},
      {"drive", "panel drive codes"},
  };
  if (options.encoder.resample_space == ResampleSpace::Linear) {
    what["d"] = "d_t = Q_b(enc(D(lin(E_t)))), reduced size: D on linear light (lin(E) ROM in uQ1." +
                std::to_string(config.linear_resample_frac_bits) + ", taps uQ0." +
                std::to_string(config.linear_gaussian_tap_frac_bits) +
                "), re-encoded to link codes by the threshold ROM, as the frame store holds it";
    what["L"] = "L = U(lin(d_t)), the bilinear U on linear light (lin(d_t) from the I ROM)";
    what["alpha"] = "alpha = U(lin(i)) (Eq. 1, linear resample space)";
    what["L_prev"] = "L_{t-1} = U(lin(d_{t-1})) for the motion test";
  }
  for (const std::string& key : order) {
    const FixedStagePlane& p = stages.at(key);
    const auto frames_of = key.substr(0, key.find(':'));
    s << "| `" << p.name << "` | " << frames_of << " | " << p.format << " | " << p.bits << " | "
      << hex_digits(p.bits) << " | " << p.size.width << "x" << p.size.height << (p.channels == 3 ? " x RGB" : "")
      << " | " << what.at(p.name) << " |\n";
  }
  return s.str();
}

}  // namespace

VectorSet generate_vectors(const PipelineOptions& options_in) {
  PipelineOptions options = options_in;
  if (!options.input.empty()) throw std::invalid_argument("trm vectors: takes a built-in --scene, not --input");
  if (options.frames < 0) throw std::invalid_argument("--frames must be >= 1");
  if (options.frames == 0) options.frames = 4;
  options.validate();
  std::unique_ptr<FrameSource> source = options.open_source();
  const FixedDecoderConfig config = fixed_config_of(options);
  FixedFrameDecoder decoder(config);
  TrmEncoder encoder(options.encoder);
  const int eyes = options.encoder.stereo ? 2 : 1;
  VectorSet set;
  std::map<std::string, FixedStagePlane> stages;  // "full:beta" -> plane shape and format (values dropped)
  std::vector<std::string> order;
  for (std::int64_t t = 0; t < options.frames; ++t) {
    const cv::Mat linear = source->linear_frame(t);
    for (int eye = 0; eye < eyes; ++eye) {
      const LinkFrame frame = encoder.encode(linear, t, eye);
      FixedStageTaps taps;
      decoder.decode(frame, taps);
      const std::string parity = frame.meta.parity == Parity::Full ? "full" : "reduced";
      char prefix[48];
      if (eyes > 1) {
        std::snprintf(prefix, sizeof prefix, "frame_%03lld_eye%d_", static_cast<long long>(t), eye);
      } else {
        std::snprintf(prefix, sizeof prefix, "frame_%03lld_", static_cast<long long>(t));
      }
      for (const FixedStagePlane& p : taps.planes) {
        if (!p.present) continue;
        set.files.push_back({t, eye, parity, p.name, std::string(prefix) + parity + "_" + p.name + ".hex",
                             plane_text(p)});
        const std::string key = parity + ":" + p.name;
        if (stages.find(key) == stages.end()) {
          FixedStagePlane shape = p;
          shape.values.clear();
          stages.emplace(key, std::move(shape));
          order.push_back(key);
        }
      }
    }
  }
  set.readme = readme_text(options, config, stages, order);
  return set;
}

std::string golden_vectors_text() {
  std::ostringstream s;
  s << "# Golden vectors of the fixed-point decoder: 64-bit FNV-1a of every stage file of `trm vectors` for these\n"
    << "# scenes (--size 24x16 --frames 4, defaults otherwise). Any change must be deliberate; regenerate with\n"
    << "#   trm vectors --update-golden tests/golden/vectors.txt\n"
    << "# <scene> <panel> <file> <fnv1a64>\n";
  for (const char* panel : {"vive", "lcd"}) {
    for (const char* scene : {"discs", "checker", "flash"}) {
      PipelineOptions options;
      options.scene = scene;
      options.panel = parse_panel(panel);
      options.width = 24;
      options.height = 16;
      options.frames = 4;
      const VectorSet set = generate_vectors(options);
      for (const VectorFile& f : set.files) {
        char hash[20];
        std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a64(f.text)));
        s << scene << " " << panel << " " << f.name << " " << hash << "\n";
      }
    }
  }
  return s.str();
}

}  // namespace trm::cli
