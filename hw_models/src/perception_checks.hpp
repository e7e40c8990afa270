// Argument checks shared by the perception models: one message shape, naming the argument.
#pragma once

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace trm::perception_detail {

inline std::string number_text(double value) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
  return ec == std::errc() ? std::string(text, end) : std::string("?");
}

[[noreturn]] inline void reject(const char* function, const char* argument, const std::string& why) {
  std::string message(function);
  message.append(": argument '").append(argument).append("' ").append(why);
  throw std::invalid_argument(message);
}

inline void require_finite(const char* function, const char* argument, double value) {
  if (!std::isfinite(value)) reject(function, argument, "must be finite, got " + number_text(value));
}

inline void require_positive(const char* function, const char* argument, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    reject(function, argument, "must be finite and > 0, got " + number_text(value));
  }
}

}  // namespace trm::perception_detail
