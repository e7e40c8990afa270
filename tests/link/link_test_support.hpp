// Synthetic link frames for the link tests (the link carries codes; it does not care how they were made).
#pragma once

#include "trm/frame.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>

namespace trm::link::test_support {

// w = max(1, floor(r * full + 0.5)), DESIGN §3 (kept here so the link tests need no encoder code).
inline int reduced_size(int full, double r) {
  const int v = static_cast<int>(r * full + 0.5);
  return v < 1 ? 1 : v;
}

// Deterministic codes with structure (gradients plus a pseudo-random texture), all < 2^bits.
inline cv::Mat synthetic_codes(int width, int height, int bits, std::uint32_t seed) {
  cv::Mat codes(height, width, CV_16UC3);
  const int max_code = (1 << bits) - 1;
  std::uint32_t state = seed * 2654435761u + 1u;
  for (int y = 0; y < height; ++y) {
    auto* row = codes.ptr<cv::Vec3w>(y);
    for (int x = 0; x < width; ++x) {
      state = state * 1664525u + 1013904223u;
      const int noise = static_cast<int>((state >> 24) & 15u);
      row[x][0] = static_cast<std::uint16_t>((x * max_code / (width > 1 ? width - 1 : 1) + noise) % (max_code + 1));
      row[x][1] = static_cast<std::uint16_t>((y * max_code / (height > 1 ? height - 1 : 1) + noise) % (max_code + 1));
      row[x][2] = static_cast<std::uint16_t>(((x ^ y) * 7 + static_cast<int>(seed)) % (max_code + 1));
    }
  }
  return codes;
}

// View `eye` of link frame t: full at the parity DESIGN §3 gives (even t full for eye 0; stereo eyes
// off-phase), reduced otherwise.
inline LinkFrame make_view(std::int64_t t, int eye, int full_width, int full_height, double r, int bits,
                           bool stereo_off_phase = true) {
  const bool full = ((t + (stereo_off_phase ? eye : 0)) % 2) == 0;
  LinkFrame f;
  f.meta.index = t;
  f.meta.eye = eye;
  f.meta.parity = full ? Parity::Full : Parity::Reduced;
  f.meta.full_width = full_width;
  f.meta.full_height = full_height;
  f.meta.width = full ? full_width : reduced_size(full_width, r);
  f.meta.height = full ? full_height : reduced_size(full_height, r);
  f.meta.bits = bits;
  f.codes = synthetic_codes(f.meta.width, f.meta.height, bits, static_cast<std::uint32_t>(t * 2 + eye + 1));
  return f;
}

inline bool same_codes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// The tests' output directory under the build tree, created on first use.
inline std::filesystem::path out_dir() {
  const std::filesystem::path dir = std::filesystem::path(TRM_BINARY_DIR) / "test_link_out";
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace trm::link::test_support
