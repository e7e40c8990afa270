// libFuzzer target for the remaining option parsers with any logic in them: --burst RATE:LENGTH
// (parse_burst) and the rig's VID:PID (parse_usb_id, --usb / --hid). The first byte picks the parser, the
// rest is the option text. Each must throw std::invalid_argument or return a value inside its domain.
#include "fuzz_support.hpp"
#include "rig/transport.hpp"
#include "trm/faults.hpp"

#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

using trm::fuzz::check;

namespace {
constexpr int kMaxBurstBits = 1000000;  // link/src/faults.cpp
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      const trm::link::BurstConfig b = trm::link::parse_burst(text);
      check(b.rate >= 0.0 && b.rate <= 1.0, "burst rate outside [0, 1]");
      check(b.length_bits >= 1 && b.length_bits <= kMaxBurstBits, "burst length outside 1..max");
      trm::link::FaultConfig config;
      config.burst = b;
      config.validate();  // what parse_burst accepts, the fault injector accepts
    } else {
      const trm::rig::UsbId id = trm::rig::parse_usb_id(text);
      check(trm::rig::parse_usb_id(id.to_string()).to_string() == id.to_string(), "VID:PID does not round-trip");
    }
  } catch (const std::invalid_argument&) {
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_options");
  }
  return 0;
}
