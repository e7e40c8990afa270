#include "trm/frame.hpp"

#include "exact_text.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace trm {

namespace {

// A row's largest code, compiled for AVX2 too and chosen at run time (GCC's function multi-versioning): the x86-64
// baseline has no unsigned 16-bit maximum (SSE4.1's), and a decoder runs this over every code of every view.
[[gnu::target_clones("avx2", "default")]] std::uint16_t row_highest(const std::uint16_t* row, std::size_t n) {
  std::uint16_t highest = 0;
  for (std::size_t i = 0; i < n; ++i) highest = std::max(highest, row[i]);
  return highest;
}

}  // namespace

std::uint16_t highest_code(const cv::Mat& codes) {
  if (codes.empty()) return 0;
  if (codes.depth() != CV_16U) throw std::invalid_argument("highest_code: codes must be CV_16U");
  const auto samples = static_cast<std::size_t>(codes.cols) * static_cast<std::size_t>(codes.channels());
  std::uint16_t highest = 0;
  for (int y = 0; y < codes.rows; ++y) highest = std::max(highest, row_highest(codes.ptr<std::uint16_t>(y), samples));
  return highest;
}

void check_view_meta(const FrameMeta& meta, const std::string& what) {
  if (meta.index < 0) throw std::invalid_argument(what + "frame index must be >= 0");
  if (meta.eye < 0) throw std::invalid_argument(what + "eye must be >= 0");
  if (meta.full_width < 1 || meta.full_height < 1 || meta.full_width > kMaxViewSide ||
      meta.full_height > kMaxViewSide) {
    std::string message = what;
    message.append("full size must be at least 1x1 and at most ")
        .append(std::to_string(kMaxViewSide))
        .append("x")
        .append(std::to_string(kMaxViewSide))
        .append(", got ")
        .append(std::to_string(meta.full_width))
        .append("x")
        .append(std::to_string(meta.full_height));
    throw std::invalid_argument(message);
  }
}

const char* to_string(Parity p) { return p == Parity::Full ? "full" : "reduced"; }

const char* to_string(Transfer t) { return t == Transfer::Srgb ? "srgb" : "gamma2.2"; }

const char* to_string(ResampleSpace s) { return s == ResampleSpace::Encoded ? "encoded" : "linear"; }

void validate_refresh_hz(double hz, const std::string& what) {
  if (!(hz >= kMinRefreshHz && hz <= kMaxRefreshHz)) {
    throw std::invalid_argument(what + " must be a refresh rate from " + detail::exact_text(kMinRefreshHz) + " to " +
                                detail::exact_text(kMaxRefreshHz) + " Hz, got " + detail::exact_text(hz));
  }
}

Transfer parse_transfer(const std::string& name) {
  if (name == "srgb") return Transfer::Srgb;
  if (name == "gamma2.2") return Transfer::Gamma22;
  throw std::invalid_argument("unknown transfer function '" + name + "' (expected srgb or gamma2.2)");
}

ResampleSpace parse_resample_space(const std::string& name) {
  if (name == "encoded") return ResampleSpace::Encoded;
  if (name == "linear") return ResampleSpace::Linear;
  throw std::invalid_argument("unknown resample space '" + name + "' (expected encoded or linear)");
}

}  // namespace trm
