#include "trm/crc32.hpp"

#include <libdeflate.h>

namespace trm {

std::uint32_t crc32_ieee(std::span<const std::uint8_t> bytes) {
  // size_t lengths: packets, payloads and metadata of any size need no chunking.
  return libdeflate_crc32(0, bytes.data(), bytes.size());
}

}  // namespace trm
