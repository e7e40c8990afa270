// The encoder configuration as JSON: one writer and one reader, for every file that records it (capture headers,
// report.json of run / decode / hw-report / vectors / sweep) and for the one that reads it back (capture replay).
#pragma once

#include "trm/encoder.hpp"

#include <nlohmann/json.hpp>

namespace trm {

// {"reduction", "sigma" (the effective sigma), "phase", "transfer", "resample_space", "bits", "stereo"}.
nlohmann::ordered_json encoder_json(const EncoderConfig& config);
// The configuration encoder_json wrote, validated as the command line validates it. Throws std::invalid_argument
// naming the first missing or malformed field, or the rule the configuration breaks.
EncoderConfig encoder_config_from_json(const nlohmann::json& json);

}  // namespace trm
