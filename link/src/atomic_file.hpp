// Whole-file output that a reader never sees half written: write a temporary file beside the target,
// then rename it into place (rename within one directory is atomic on POSIX).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace trm::link::detail {

// A temporary name in the same directory as `path`, unique to this process and call.
std::filesystem::path temporary_sibling(const std::filesystem::path& path);

// Throws std::runtime_error naming the path on failure; leaves no temporary file behind.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

}  // namespace trm::link::detail
