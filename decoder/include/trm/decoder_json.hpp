// The decoder configurations as JSON: one writer and one reader each, for the reports that record a decoder
// (run, hw-report, vectors) and for whatever builds a decoder from a report (a testbench, a notebook).
#pragma once

#include "trm/decoder.hpp"
#include "trm/fixed_decoder.hpp"

#include <nlohmann/json.hpp>

namespace trm {

// {"encoder": encoder_json, "sensitivity": s (the string "inf" for +inf), "panel": the panel's JSON, "output_bits",
// "lcd_history": "wanted" | "contributed"}. record_stages and report_planes are run-time choices, not configuration:
// not written.
nlohmann::ordered_json decoder_json(const DecoderConfig& config);
// {"decoder": decoder_json, "formats": {every fraction-bit and table-size field by its C++ name}, "residual":
// {"int_bits", "frac_bits", "signed", "quant", "overflow"}, "skip_unneeded"}.
nlohmann::ordered_json fixed_decoder_json(const FixedDecoderConfig& config);
// The readers: a configuration as the writers wrote it, validated as the decoders validate it. Throws
// std::invalid_argument naming the first missing or malformed field, or the rule the configuration breaks.
DecoderConfig decoder_config_from_json(const nlohmann::json& json);
FixedDecoderConfig fixed_decoder_config_from_json(const nlohmann::json& json);

// The streaming decoder as hardware (FixedStreamingReport): buffers, ROMs, arithmetic per stage, latency, on-/off-chip
// totals and the paper's frame-store comparison; the one writer for `trm hw-report`, `trm run`'s report.json and
// the C API (trm_c.h).
nlohmann::ordered_json hardware_json(const FixedStreamingReport& report);
// The document `trm hw-report` writes: {"parameters": {"size": [w, h], "decoder": fixed_decoder_json}, "hardware":
// hardware_json}.
nlohmann::ordered_json hw_report_json(const FixedDecoderConfig& config, cv::Size full,
                                      const FixedStreamingReport& report);

}  // namespace trm
