#include "rig/transport.hpp"

#include <cctype>
#include <cstdio>
#include <optional>

namespace trm::rig {

const char* to_string(RigErrorKind kind) {
  switch (kind) {
    case RigErrorKind::NoDevice: return "no_device";
    case RigErrorKind::PermissionDenied: return "permission_denied";
    case RigErrorKind::Busy: return "busy";
    case RigErrorKind::EndpointMissing: return "endpoint_missing";
    case RigErrorKind::Timeout: return "timeout";
    case RigErrorKind::Disconnected: return "disconnected";
    case RigErrorKind::Stalled: return "stalled";
    case RigErrorKind::RigReported: return "rig_error";
    case RigErrorKind::Io: return "io_error";
  }
  return "unknown";
}

std::string UsbId::to_string() const {
  char text[16];
  std::snprintf(text, sizeof text, "%04x:%04x", vendor, product);
  return text;
}

namespace {

// 1..4 hex digits, optionally prefixed with 0x.
std::optional<std::uint16_t> parse_hex16(std::string text) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) text = text.substr(2);
  if (text.empty() || text.size() > 4) return std::nullopt;
  unsigned value = 0;
  for (char c : text) {
    const int digit = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                      : (c >= 'a' && c <= 'f')                    ? c - 'a' + 10
                      : (c >= 'A' && c <= 'F')                    ? c - 'A' + 10
                                                                  : -1;
    if (digit < 0) return std::nullopt;
    value = value * 16 + static_cast<unsigned>(digit);
  }
  return static_cast<std::uint16_t>(value);
}

}  // namespace

UsbId parse_usb_id(const std::string& text) {
  const auto colon = text.find(':');
  const auto vendor = colon == std::string::npos ? std::nullopt : parse_hex16(text.substr(0, colon));
  const auto product = colon == std::string::npos ? std::nullopt : parse_hex16(text.substr(colon + 1));
  if (!vendor || !product)
    throw std::invalid_argument("'" + text + "' is not a USB VID:PID (expected four hex digits each, e.g. 1234:5678)");
  return UsbId{*vendor, *product};
}

}  // namespace trm::rig
