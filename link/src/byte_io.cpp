#include "byte_io.hpp"

#include <zlib.h>

namespace trm::link::detail {

std::uint32_t crc32_of(std::span<const std::uint8_t> bytes) {
  // crc32_z takes a size_t length, so packets and metadata of any size need no chunking.
  return static_cast<std::uint32_t>(crc32_z(crc32_z(0L, Z_NULL, 0), bytes.data(), bytes.size()));
}

}  // namespace trm::link::detail
