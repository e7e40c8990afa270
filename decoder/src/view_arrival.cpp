// The input checks, the concealment classification and the lost-view output every decoder shares
// (view_arrival.hpp).
#include "view_arrival.hpp"

#include "trm/resample.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <thread>
#include <vector>

namespace trm::detail {
namespace {

std::string size_text(int width, int height) { return std::to_string(width).append("x").append(std::to_string(height)); }

}  // namespace

std::string frame_name(const FrameMeta& meta) {
  return std::string(to_string(meta.parity)) + " frame t=" + std::to_string(meta.index) +
         " eye=" + std::to_string(meta.eye);
}

namespace {

// The view's metadata against the decoder's link format; returns the size its codes must have.
cv::Size check_header_format(const FrameMeta& meta, const EncoderConfig& link, const std::string& what) {
  check_view_meta(meta, what);
  if (meta.bits != link.bits) {
    throw std::invalid_argument(what + "link bits " + std::to_string(meta.bits) + " but the decoder expects " +
                                std::to_string(link.bits));
  }
  if (meta.transfer != link.transfer) {
    throw std::invalid_argument(what + "transfer " + to_string(meta.transfer) + " but the decoder expects " +
                                to_string(link.transfer));
  }
  const cv::Size full(meta.full_width, meta.full_height);
  return meta.parity == Parity::Full
             ? full
             : cv::Size(reduced_size(full.width, link.reduction), reduced_size(full.height, link.reduction));
}

// " but a <parity> frame of a WxH view at r=R must be wxh"
std::string expected_size_text(const FrameMeta& meta, const EncoderConfig& link, cv::Size expected) {
  return std::string(" but a ") + to_string(meta.parity) + " frame of a " + size_text(meta.full_width, meta.full_height) +
         " view at r=" + std::to_string(link.reduction) + " must be " + size_text(expected.width, expected.height);
}

}  // namespace

void check_link_frame(const LinkFrame& frame, const EncoderConfig& link, const std::string& who, int threads) {
  const FrameMeta& meta = frame.meta;
  const std::string what = who + ": " + frame_name(meta) + ": ";
  const cv::Size expected = check_header_format(meta, link, what);
  if (frame.codes.empty() || frame.codes.type() != CV_16UC3) {
    throw std::invalid_argument(what + "codes must be a non-empty CV_16UC3 image");
  }
  // The codes against their own metadata first (a mismatch there is named as such), then against the view size:
  // both before any geometry of the view is built, so a frame claiming a view it cannot be part of allocates nothing.
  const std::string codes_size = size_text(frame.codes.cols, frame.codes.rows);
  if (frame.codes.cols != meta.width || frame.codes.rows != meta.height) {
    throw std::invalid_argument(what + "codes are " + codes_size + " but the metadata says " +
                                size_text(meta.width, meta.height));
  }
  if (frame.codes.size() != expected) {
    throw std::invalid_argument(what + "codes are " + codes_size + expected_size_text(meta, link, expected));
  }
  // Bands of at least 64 rows each (a thread costs about as much as scanning a few rows).
  constexpr int kMinScanRows = 64;
  const int bands = std::clamp(std::min(threads, frame.codes.rows / kMinScanRows), 1, kMaxDecoderThreads);
  std::array<std::uint16_t, kMaxDecoderThreads> band_highest{};
  const auto scan = [&](int b) {
    const int first = frame.codes.rows * b / bands;
    const int end = frame.codes.rows * (b + 1) / bands;
    band_highest[static_cast<std::size_t>(b)] = highest_code(frame.codes.rowRange(first, end));
  };
  {
    std::vector<std::jthread> helpers;
    for (int b = 1; b < bands; ++b) helpers.emplace_back(scan, b);
    scan(0);
  }  // joined
  const int highest = *std::max_element(band_highest.begin(), band_highest.begin() + bands);
  if (highest > (1 << link.bits) - 1) {
    throw std::invalid_argument(what + "code " + std::to_string(highest) + " exceeds the " +
                                std::to_string(link.bits) + "-bit range");
  }
}

void check_view_header(const FrameMeta& meta, const EncoderConfig& link, const std::string& who) {
  const std::string what = who + ": " + frame_name(meta) + ": ";
  const cv::Size expected = check_header_format(meta, link, what);
  if (cv::Size(meta.width, meta.height) != expected) {
    throw std::invalid_argument(what + "the metadata says " + size_text(meta.width, meta.height) +
                                expected_size_text(meta, link, expected));
  }
}

void check_line_codes(const FrameMeta& meta, int line, std::span<const std::uint16_t> codes, int bits,
                      const std::string& who) {
  const std::uint16_t highest = codes.empty() ? 0 : *std::max_element(codes.begin(), codes.end());
  if (highest > (1 << bits) - 1) {
    throw std::invalid_argument(who + ": " + frame_name(meta) + ": line " + std::to_string(line) + ": code " +
                                std::to_string(highest) + " exceeds the " + std::to_string(bits) + "-bit range");
  }
}

void check_lost_view(const FrameMeta& meta, const std::string& who) {
  check_view_meta(meta, who + ": lost " + frame_name(meta) + ": ");
}

Arrival classify_arrival(const LinkFrame& frame, std::span<const std::uint8_t> line_intact, Concealment& out,
                         const std::string& who) {
  if (line_intact.empty()) return Arrival::Whole;
  if (line_intact.size() != static_cast<std::size_t>(frame.codes.rows)) {
    throw std::invalid_argument(who + ": line mask has " + std::to_string(line_intact.size()) +
                                " entries for a view of " + std::to_string(frame.codes.rows) + " lines");
  }
  out = Concealment();
  out.intact = line_intact;
  out.first_intact = -1;
  for (int y = 0; y < frame.codes.rows; ++y) {
    if (out.lost(y)) {
      ++out.lost_lines;
    } else if (out.first_intact < 0) {
      out.first_intact = y;
    }
  }
  if (out.first_intact < 0) return Arrival::Lost;
  if (out.lost_lines == 0) return Arrival::Whole;
  return Arrival::Partial;
}

cv::Mat concealed_codes(const cv::Mat& codes, const Concealment& c) {
  cv::Mat out = codes.clone();
  for (int y = 0; y < codes.rows; ++y) {
    if (!c.lost(y)) continue;
    if (!c.substitute.empty()) {
      c.substitute.row(y).copyTo(out.row(y));
      continue;
    }
    // The nearest intact line above, else (lines above the first intact one) below. Lines above y are already
    // concealed, so the line just above holds the nearest intact line above.
    out.row(y < c.first_intact ? c.first_intact : y - 1).copyTo(out.row(y));
  }
  return out;
}

}  // namespace trm::detail

namespace trm {

DecodedFrame lost_view_output(const FrameMeta& meta, const DecodedFrame* last, bool report_planes) {
  const cv::Size full(meta.full_width, meta.full_height);
  DecodedFrame out;
  if (last != nullptr) {
    out = *last;
    out.stages.reset();
  } else {
    out.drive_codes = cv::Mat::zeros(full, CV_16UC3);
    if (report_planes) {
      out.wanted_linear = cv::Mat::zeros(full, CV_64FC3);
      out.drive = cv::Mat::zeros(full, CV_64FC3);
      out.emitted_linear = cv::Mat::zeros(full, CV_64FC3);
    }
  }
  out.meta = meta;
  out.meta.width = full.width;
  out.meta.height = full.height;
  out.stats = FrameStats();
  out.stats.frame_lost = true;
  out.stats.concealed_lines = meta.height;
  return out;
}

}  // namespace trm
