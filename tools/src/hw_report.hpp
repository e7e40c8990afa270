// The decoder as hardware (DESIGN §5): the fixed-point configuration the command-line options describe, and the
// text form of a FixedStreamingReport shared by `trm hw-report` and `trm run` (its JSON: trm::hardware_json).
#pragma once

#include "pipeline.hpp"

#include "trm/decoder_json.hpp"
#include "trm/fixed_decoder.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// A human-readable summary of hardware_json's content (trm/decoder_json.hpp).
std::string hardware_summary(const Json& hardware);


}  // namespace trm::cli
