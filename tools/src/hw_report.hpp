// The decoder as hardware (DESIGN §5): the fixed-point configuration the command-line options describe, and the
// one JSON / text form of a FixedStreamingReport shared by `trm hw-report` and `trm run`'s report.json.
#pragma once

#include "pipeline.hpp"

#include "trm/fixed_decoder.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// Buffers, ROMs, arithmetic per stage, latency, on-/off-chip totals and the paper's frame-store comparison.
Json hardware_json(const FixedStreamingReport& report);
// A human-readable summary of hardware_json's content.
std::string hardware_summary(const Json& hardware);


}  // namespace trm::cli
