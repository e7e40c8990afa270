// Wall time since a point of the steady clock, in seconds: the one timing rule of the tools' reports.
#pragma once

#include <chrono>

namespace trm::cli {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace trm::cli
