// libFuzzer target for the --link preset parser (parse_link_preset). The input is the option text.
// The parser must throw std::invalid_argument or return a preset whose fields it promises: the name as
// given, a finite rate > 0 Gbit/s and a coding efficiency in (0, 1]. What a caller then does with an
// absurd but valid capacity (e.g. custom:1e300:1) is outside this target.
#include "fuzz_support.hpp"
#include "trm/presets.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

using trm::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const trm::link::LinkPreset p = trm::link::parse_link_preset(text);
    check(p.name == text, "preset name differs from the text");
    check(std::isfinite(p.raw_gbps) && p.raw_gbps > 0.0, "rate not finite and > 0");
    check(p.data_gbps() <= trm::link::kMaxLinkGbps, "data rate beyond kMaxLinkGbps");
    check(p.efficiency > 0.0 && p.efficiency <= 1.0, "efficiency outside (0, 1]");
    check(!p.description.empty(), "no description");
  } catch (const std::invalid_argument& e) {
    check(std::string(e.what()).find("link preset") != std::string::npos, "message does not name the preset");
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_link_preset");
  }
  return 0;
}
