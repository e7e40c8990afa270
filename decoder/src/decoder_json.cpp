#include "trm/decoder_json.hpp"

#include "trm/encoder_json.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace trm {

namespace {

// The integer fields of FixedDecoderConfig by name: the one list the writer and the reader both walk.
const std::pair<const char*, int FixedDecoderConfig::*> kFormatFields[] = {
    {"linear_frac_bits", &FixedDecoderConfig::linear_frac_bits},
    {"gaussian_tap_frac_bits", &FixedDecoderConfig::gaussian_tap_frac_bits},
    {"gaussian_line_frac_bits", &FixedDecoderConfig::gaussian_line_frac_bits},
    {"linear_resample_frac_bits", &FixedDecoderConfig::linear_resample_frac_bits},
    {"linear_gaussian_tap_frac_bits", &FixedDecoderConfig::linear_gaussian_tap_frac_bits},
    {"bilinear_weight_frac_bits", &FixedDecoderConfig::bilinear_weight_frac_bits},
    {"upsample_frac_bits", &FixedDecoderConfig::upsample_frac_bits},
    {"eotf_segments_per_code_log2", &FixedDecoderConfig::eotf_segments_per_code_log2},
    {"luma_weight_frac_bits", &FixedDecoderConfig::luma_weight_frac_bits},
    {"reciprocal_entries", &FixedDecoderConfig::reciprocal_entries},
    {"sensitivity_frac_bits", &FixedDecoderConfig::sensitivity_frac_bits},
    {"exp_input_frac_bits", &FixedDecoderConfig::exp_input_frac_bits},
    {"exp_entries", &FixedDecoderConfig::exp_entries},
    {"drive_frac_bits", &FixedDecoderConfig::drive_frac_bits},
    {"drive_segments_per_octave", &FixedDecoderConfig::drive_segments_per_octave},
    {"lcd_segments_per_octave", &FixedDecoderConfig::lcd_segments_per_octave},
};

[[noreturn]] void reject(const std::string& why) { throw std::invalid_argument("decoder configuration: " + why); }

const nlohmann::json& field(const nlohmann::json& in, const char* key) {
  if (!in.is_object()) reject(std::string("expected an object holding \"") + key + "\", got " + in.dump());
  const auto found = in.find(key);
  if (found == in.end()) reject(std::string("missing \"") + key + "\"");
  return *found;
}

int int_field(const nlohmann::json& in, const char* key) {
  const nlohmann::json& v = field(in, key);
  if (!v.is_number_integer()) reject(std::string("\"") + key + "\" must be a whole number, got " + v.dump());
  return v.get<int>();
}

bool bool_field(const nlohmann::json& in, const char* key) {
  const nlohmann::json& v = field(in, key);
  if (!v.is_boolean()) reject(std::string("\"") + key + "\" must be true or false, got " + v.dump());
  return v.get<bool>();
}

std::string string_field(const nlohmann::json& in, const char* key) {
  const nlohmann::json& v = field(in, key);
  if (!v.is_string()) reject(std::string("\"") + key + "\" must be a string, got " + v.dump());
  return v.get<std::string>();
}

}  // namespace

nlohmann::ordered_json decoder_json(const DecoderConfig& config) {
  nlohmann::ordered_json j;
  j["encoder"] = encoder_json(config.link);
  j["sensitivity"] = std::isinf(config.sensitivity) ? nlohmann::ordered_json("inf")
                                                    : nlohmann::ordered_json(config.sensitivity);
  j["panel"] = config.panel;
  j["output_bits"] = config.output_bits;
  j["lcd_history"] = config.lcd_history == LcdHistory::Contributed ? "contributed" : "wanted";
  return j;
}

nlohmann::ordered_json fixed_decoder_json(const FixedDecoderConfig& config) {
  nlohmann::ordered_json j;
  j["decoder"] = decoder_json(config.decoder);
  nlohmann::ordered_json formats;
  for (const auto& [name, member] : kFormatFields) formats[name] = config.*member;
  j["formats"] = formats;
  j["residual"] = {{"int_bits", config.residual.int_bits},
                   {"frac_bits", config.residual.frac_bits},
                   {"signed", config.residual.is_signed},
                   {"quant", fx::to_string(config.residual.quant)},
                   {"overflow", fx::to_string(config.residual.overflow)}};
  j["skip_unneeded"] = config.skip_unneeded;
  return j;
}

DecoderConfig decoder_config_from_json(const nlohmann::json& json) {
  DecoderConfig config;
  try {
    config.link = encoder_config_from_json(field(json, "encoder"));
  } catch (const std::invalid_argument& e) {
    reject(std::string("\"encoder\": ") + e.what());
  }
  const nlohmann::json& s = field(json, "sensitivity");
  if (s.is_string() && s.get<std::string>() == "inf") {
    config.sensitivity = std::numeric_limits<double>::infinity();
  } else if (s.is_number()) {
    config.sensitivity = s.get<double>();
  } else {
    reject("\"sensitivity\" must be a number or \"inf\", got " + s.dump());
  }
  try {
    field(json, "panel").get_to(config.panel);
  } catch (const std::invalid_argument& e) {
    reject(std::string("\"panel\": ") + e.what());
  }
  config.output_bits = int_field(json, "output_bits");
  const std::string history = string_field(json, "lcd_history");
  if (history == "wanted") {
    config.lcd_history = LcdHistory::Wanted;
  } else if (history == "contributed") {
    config.lcd_history = LcdHistory::Contributed;
  } else {
    reject("\"lcd_history\" must be \"wanted\" or \"contributed\", got \"" + history + "\"");
  }
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    reject(e.what());
  }
  return config;
}

FixedDecoderConfig fixed_decoder_config_from_json(const nlohmann::json& json) {
  FixedDecoderConfig config;
  config.decoder = decoder_config_from_json(field(json, "decoder"));
  const nlohmann::json& formats = field(json, "formats");
  for (const auto& [name, member] : kFormatFields) config.*member = int_field(formats, name);
  const nlohmann::json& residual = field(json, "residual");
  config.residual.int_bits = int_field(residual, "int_bits");
  config.residual.frac_bits = int_field(residual, "frac_bits");
  config.residual.is_signed = bool_field(residual, "signed");
  const std::string quant = string_field(residual, "quant");
  const std::string overflow = string_field(residual, "overflow");
  bool quant_known = false, overflow_known = false;
  for (const fx::Quant q : fx::kAllQuantModes) {
    if (quant == fx::to_string(q)) config.residual.quant = q, quant_known = true;
  }
  for (const fx::Overflow o : fx::kAllOverflowModes) {
    if (overflow == fx::to_string(o)) config.residual.overflow = o, overflow_known = true;
  }
  if (!quant_known) reject("\"residual\": unknown rounding mode \"" + quant + "\"");
  if (!overflow_known) reject("\"residual\": unknown overflow mode \"" + overflow + "\"");
  config.skip_unneeded = bool_field(json, "skip_unneeded");
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    reject(e.what());
  }
  return config;
}

namespace {

bool on_chip(const FixedBufferReport& b) { return b.name.rfind("line:", 0) == 0; }

}  // namespace

nlohmann::ordered_json hardware_json(const FixedStreamingReport& r) {
  nlohmann::ordered_json hw;
  hw["full_size"] = {r.full.width, r.full.height};
  hw["reduced_size"] = {r.reduced.width, r.reduced.height};
  hw["full_frame_latency_lines"] = r.full_latency_lines;
  hw["reduced_frame_latency_lines"] = r.reduced_latency_lines;
  nlohmann::ordered_json buffers = nlohmann::ordered_json::array();
  std::int64_t total_bits = 0;
  std::int64_t line_bits = 0;
  std::int64_t frame_bits = 0;
  for (const auto& b : r.buffers) {
    buffers.push_back({{"name", b.name}, {"kind", on_chip(b) ? "line buffer" : "frame store"}, {"lines", b.lines},
                       {"samples", b.samples}, {"bits", b.bits}, {"total_bits", b.total_bits()}});
    total_bits += b.total_bits();
    (on_chip(b) ? line_bits : frame_bits) += b.total_bits();
  }
  hw["buffers"] = buffers;
  hw["total_bits"] = total_bits;  // line buffers + frame stores
  nlohmann::ordered_json roms = nlohmann::ordered_json::array();
  std::int64_t rom_bits = 0;
  for (const auto& rom : r.roms) {
    roms.push_back({{"name", rom.name}, {"entries", rom.entries}, {"word_bits", rom.word_bits}, {"count", rom.count},
                    {"total_bits", rom.total_bits()}});
    rom_bits += rom.total_bits();
  }
  hw["roms"] = roms;
  // Not cv::Size::area(): an int, which overflows from 2^31 pixels.
  const double pixels = static_cast<double>(r.full.width) * r.full.height;
  nlohmann::ordered_json arithmetic = nlohmann::ordered_json::array();
  nlohmann::ordered_json per_pixel;
  for (const char* kind : {"full", "reduced"}) per_pixel[kind] = {{"adders", 0.0}, {"multipliers", 0.0}, {"comparators", 0.0}};
  for (const auto& a : r.arithmetic) {
    const double scale = pixels > 0 ? static_cast<double>(a.evaluations) / pixels : 0.0;
    arithmetic.push_back({{"stage", a.stage}, {"frame", a.frame}, {"evaluated_per", a.evaluated_per},
                          {"evaluations", a.evaluations}, {"adders", a.adders}, {"multipliers", a.multipliers},
                          {"comparators", a.comparators}, {"rom_reads", a.rom_reads},
                          {"adders_per_pixel", a.adders * scale}, {"multipliers_per_pixel", a.multipliers * scale},
                          {"comparators_per_pixel", a.comparators * scale}});
    for (const char* kind : {"full", "reduced"}) {
      if (a.frame != kind && a.frame != "both") continue;
      per_pixel[kind]["adders"] = per_pixel[kind]["adders"].get<double>() + a.adders * scale;
      per_pixel[kind]["multipliers"] = per_pixel[kind]["multipliers"].get<double>() + a.multipliers * scale;
      per_pixel[kind]["comparators"] = per_pixel[kind]["comparators"].get<double>() + a.comparators * scale;
    }
  }
  hw["arithmetic"] = arithmetic;
  hw["arithmetic_per_output_pixel"] = per_pixel;
  hw["totals"] = {{"line_buffer_bits", line_bits},
                  {"rom_bits", rom_bits},
                  {"on_chip_bits", line_bits + rom_bits},
                  {"frame_store_bits", frame_bits},
                  {"off_chip_bits", frame_bits}};
  const std::int64_t saved = r.paper_frame_store_bits - r.model_frame_store_bits;
  hw["concealment"] = r.concealment;
  hw["paper_comparison"] = {
      {"description", "paper Sec. 9: full-size previous frame (link codes) + full-size residual; this model: "
                      "reduced-size d_t (link codes) + full-size residual (LCD stores and the held output for "
                      "lost views excluded from both)"},
      {"paper_frame_store_bits", r.paper_frame_store_bits},
      {"model_frame_store_bits", r.model_frame_store_bits},
      {"saved_bits", saved},
      {"saved_percent", r.paper_frame_store_bits > 0 ? 100.0 * static_cast<double>(saved) /
                                                           static_cast<double>(r.paper_frame_store_bits)
                                                     : 0.0}};
  return hw;
}

nlohmann::ordered_json hw_report_json(const FixedDecoderConfig& config, cv::Size full,
                                      const FixedStreamingReport& report) {
  nlohmann::ordered_json out;
  out["parameters"] = {{"size", {full.width, full.height}}, {"decoder", fixed_decoder_json(config)}};
  out["hardware"] = hardware_json(report);
  return out;
}

}  // namespace trm
