#include "bit_packing.hpp"

namespace trm::link::detail {

void pack_codes(const cv::Mat& codes, const cv::Rect& rect, int bits, std::vector<std::uint8_t>& out) {
  const int components = rect.width * 3;
  if (bits == 8) {
    out.reserve(out.size() + static_cast<std::size_t>(components) * static_cast<std::size_t>(rect.height));
    for (int y = rect.y; y < rect.y + rect.height; ++y) {
      const std::uint16_t* row = codes.ptr<std::uint16_t>(y) + rect.x * 3;
      for (int i = 0; i < components; ++i) out.push_back(static_cast<std::uint8_t>(row[i]));
    }
    return;
  }
  // General MSB-first bit writer: `acc` holds `held` pending bits in its low end.
  std::uint64_t acc = 0;
  int held = 0;
  for (int y = rect.y; y < rect.y + rect.height; ++y) {
    const std::uint16_t* row = codes.ptr<std::uint16_t>(y) + rect.x * 3;
    for (int i = 0; i < components; ++i) {
      acc = (acc << bits) | row[i];
      held += bits;
      while (held >= 8) {
        held -= 8;
        out.push_back(static_cast<std::uint8_t>(acc >> held));
      }
      acc &= (std::uint64_t{1} << held) - 1u;
    }
  }
  if (held > 0) out.push_back(static_cast<std::uint8_t>(acc << (8 - held)));
}

bool raw_padding_is_zero(std::span<const std::uint8_t> payload, int bits, const cv::Rect& rect) {
  const std::uint64_t total_bits = static_cast<std::uint64_t>(rect.width) * 3u * static_cast<std::uint64_t>(rect.height) *
                                   static_cast<std::uint64_t>(bits);
  const int padding = static_cast<int>(payload.size() * 8u - total_bits);
  return padding <= 0 || (payload.back() & ((1u << padding) - 1u)) == 0;
}

bool unpack_codes(std::span<const std::uint8_t> payload, int bits, cv::Mat& codes, const cv::Rect& rect) {
  const int components = rect.width * 3;
  if (!raw_padding_is_zero(payload, bits, rect)) return false;
  if (bits == 8) {
    // Through restrict pointers: a byte load may alias the stores otherwise, which keeps the loop scalar.
    const std::uint8_t* src = payload.data();
    for (int y = rect.y; y < rect.y + rect.height; ++y, src += components) {
      const std::uint8_t* __restrict in = src;
      std::uint16_t* __restrict row = codes.ptr<std::uint16_t>(y) + rect.x * 3;
      for (int i = 0; i < components; ++i) row[i] = in[i];
    }
    return true;
  }
  const std::uint32_t mask = (1u << bits) - 1u;
  std::uint64_t acc = 0;
  int held = 0;
  std::size_t next = 0;
  for (int y = rect.y; y < rect.y + rect.height; ++y) {
    std::uint16_t* row = codes.ptr<std::uint16_t>(y) + rect.x * 3;
    for (int i = 0; i < components; ++i) {
      while (held < bits) {  // the caller checked the payload size, so `next` stays in range
        acc = (acc << 8) | payload[next++];
        held += 8;
      }
      held -= bits;
      row[i] = static_cast<std::uint16_t>((acc >> held) & mask);
      acc &= (std::uint64_t{1} << held) - 1u;
    }
  }
  return true;
}

}  // namespace trm::link::detail
