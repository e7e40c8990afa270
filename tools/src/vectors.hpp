// Golden vectors for RTL test benches: every stage's integer plane of the frame-at-a-time fixed-point decoder, one
// text file per stage and frame, and their compact checked-in form (one 64-bit FNV-1a hash per file).
#pragma once

#include "pipeline.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace trm::cli {

struct VectorFile {
  std::int64_t frame = 0;
  int eye = 0;
  std::string parity;  // "full" | "reduced"
  std::string stage;   // FixedStagePlane::name
  std::string name;    // file name, e.g. frame_000_full_beta.hex
  std::string text;    // one line of hex words per image line
};

struct VectorSet {
  std::vector<VectorFile> files;
  std::string readme;  // the format and every stage's Q format, from the decoder configuration
};

// Encodes options.frames frames of options.scene (default 4) and decodes them with FixedFrameDecoder, recording
// every stage. Throws std::invalid_argument on bad options.
VectorSet generate_vectors(const PipelineOptions& options);

// 64-bit FNV-1a of the bytes (offset basis 14695981039346656037, prime 1099511628211).
std::uint64_t fnv1a64(const std::string& bytes);

// The checked-in golden set: small scenes (24x16, 4 frames) on an OLED and an LCD panel. One line per stage file:
// "<scene> <panel> <file name> <16 hex digits of fnv1a64>", '#' comment lines first.
std::string golden_vectors_text();

}  // namespace trm::cli
