// The decoders by name: one line each.
#include "trm/decoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/reference_decoder.hpp"

#include <functional>
#include <stdexcept>
#include <utility>

namespace trm {

namespace {

using Factory = std::function<std::unique_ptr<HeadsetDecoder>(const FixedDecoderConfig&)>;

const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> decoders = {
      {"reference", [](const FixedDecoderConfig& c) { return std::make_unique<ReferenceDecoder>(c.decoder); }},
      {"fixed", [](const FixedDecoderConfig& c) { return std::make_unique<FixedStreamingDecoder>(c); }},
      {"fixed-frame", [](const FixedDecoderConfig& c) { return std::make_unique<FixedFrameDecoder>(c); }},
  };
  return decoders;
}

}  // namespace

const std::vector<std::string>& decoder_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& [name, factory] : registry()) out.push_back(name);
    return out;
  }();
  return names;
}

void check_decoder_name(const std::string& name) {
  for (const std::string& known : decoder_names()) {
    if (known == name) return;
  }
  std::string list;
  for (const std::string& known : decoder_names()) list += (list.empty() ? "" : ", ") + known;
  throw std::invalid_argument("unknown decoder implementation '" + name + "' (available: " + list + ")");
}

std::unique_ptr<HeadsetDecoder> make_decoder(const std::string& name, const FixedDecoderConfig& config) {
  check_decoder_name(name);
  for (const auto& [known, factory] : registry()) {
    if (known == name) return factory(config);
  }
  return nullptr;  // not reached: check_decoder_name threw
}

}  // namespace trm
