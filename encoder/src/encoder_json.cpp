#include "trm/encoder_json.hpp"

#include <stdexcept>
#include <string>

namespace trm {

nlohmann::ordered_json encoder_json(const EncoderConfig& config) {
  nlohmann::ordered_json j;
  j["reduction"] = config.reduction;
  j["sigma"] = config.effective_sigma();
  j["phase"] = config.phase;
  j["transfer"] = to_string(config.transfer);
  j["resample_space"] = to_string(config.resample_space);
  j["bits"] = config.bits;
  j["stereo"] = config.stereo;
  return j;
}

EncoderConfig encoder_config_from_json(const nlohmann::json& json) {
  if (!json.is_object()) throw std::invalid_argument("the encoder configuration is not a JSON object");
  EncoderConfig config;
  const auto field = [&json](const char* name) -> const nlohmann::json& {
    if (!json.contains(name)) throw std::invalid_argument(std::string("the encoder configuration has no '") + name + "'");
    return json.at(name);
  };
  try {
    config.reduction = field("reduction").get<double>();
    config.sigma = field("sigma").get<double>();
    config.phase = field("phase").get<int>();
    config.transfer = parse_transfer(field("transfer").get<std::string>());
    config.resample_space = parse_resample_space(field("resample_space").get<std::string>());
    config.bits = field("bits").get<int>();
    config.stereo = field("stereo").get<bool>();
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("the encoder configuration has a field of the wrong type: ") + e.what());
  }
  config.validate();
  return config;
}

}  // namespace trm
