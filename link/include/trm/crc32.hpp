// CRC-32 as IEEE 802.3, zlib, PNG and gzip define it (polynomial 0x04C11DB7 reflected, initial value and final XOR
// 0xFFFFFFFF; check value 0xCBF43926 over "123456789"): the link packets', the captures' and the rig frames' checksum.
#pragma once

#include <cstdint>
#include <span>

namespace trm {

// libdeflate's carry-less-multiply CRC (PCLMULQDQ / VPCLMULQDQ where the CPU has them, chosen at run time).
std::uint32_t crc32_ieee(std::span<const std::uint8_t> bytes);

}  // namespace trm
