// The decoder as hardware (DESIGN §5): the fixed-point configuration the command-line options describe, and the
// one JSON / text form of a FixedStreamingReport shared by `trm hw-report` and `trm run`'s report.json.
#pragma once

#include "pipeline.hpp"

#include "trm/fixed_decoder.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// The decoder configuration of the shared pipeline options (link, sensitivity, panel, output bits, LCD history)
// with the default fixed-point formats.
FixedDecoderConfig fixed_config_of(const PipelineOptions& options);

// Residual store of total signed width `bits` (sQ2.(bits - 2)); throws std::invalid_argument outside
// [3, 2 + linear_frac_bits] (and 32).
fx::RuntimeFormat residual_format_of_bits(int bits, int linear_frac_bits);

// Buffers, ROMs, arithmetic per stage, latency, on-/off-chip totals and the paper's frame-store comparison.
Json hardware_json(const FixedStreamingReport& report);
// A human-readable summary of hardware_json's content.
std::string hardware_summary(const Json& hardware);


}  // namespace trm::cli
