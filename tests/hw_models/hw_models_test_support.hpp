// Shared helpers of the hw_models tests.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace trm::test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `call` must throw std::invalid_argument whose message names `needle`.
inline void expect_invalid(const std::function<void()>& call, const std::string& needle) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one naming " << needle;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
  }
}

}  // namespace trm::test
