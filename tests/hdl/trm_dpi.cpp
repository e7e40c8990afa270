// The DPI-C side of trm_decoder_model.sv: the C API (trm/trm_c.h) in the argument types SystemVerilog passes.
// Kept thin on purpose: every decision (view order, handshakes, checking) is in the SystemVerilog, so a hardware team
// reads one language for the behaviour and this file only for the type conversions.
#include "trm/trm_c.h"

#include <svdpi.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Messages of the shim's own refusals (file not readable, a code that does not fit 16 bits) for a handle-less call;
// the C API's own messages are read through trm_decoder_last_error.
thread_local std::string shim_error;

struct Handle {
  trm_decoder* decoder = nullptr;
  std::string error;  // a refusal of the shim on this handle, cleared by the next successful call
  std::vector<std::uint16_t> line;
};

Handle* handle_of(void* h) { return static_cast<Handle*>(h); }

}  // namespace

extern "C" {

// Reads the configuration file (a `trm vectors` / `trm hw-report` report.json, or the decoder object alone) and
// creates a decoder; null on failure, with the reason in trm_dpi_last_error(null).
void* trm_dpi_create(const char* config_path) {
  std::ifstream in(config_path ? config_path : "", std::ios::binary);
  if (!in) {
    shim_error = std::string("cannot read the decoder configuration '") + (config_path ? config_path : "") + "'";
    return nullptr;
  }
  std::ostringstream text;
  text << in.rdbuf();
  trm_decoder* decoder = nullptr;
  if (trm_decoder_create_json(text.str().c_str(), &decoder) != TRM_OK) {
    shim_error = std::string(config_path) + ": " + trm_last_error();
    return nullptr;
  }
  auto* h = new Handle;
  h->decoder = decoder;
  return h;
}

void trm_dpi_destroy(void* h) {
  if (!h) return;
  trm_decoder_destroy(handle_of(h)->decoder);
  delete handle_of(h);
}

const char* trm_dpi_last_error(void* h) {
  if (!h) return shim_error.empty() ? trm_last_error() : shim_error.c_str();
  if (!handle_of(h)->error.empty()) return handle_of(h)->error.c_str();
  return trm_decoder_last_error(handle_of(h)->decoder);
}

int trm_dpi_begin_view(void* h, int full_width, int full_height, int kind, int eye, long long index) {
  if (!h) return trm_decoder_begin_view(nullptr, full_width, full_height, kind, eye, index);
  handle_of(h)->error.clear();
  return trm_decoder_begin_view(handle_of(h)->decoder, full_width, full_height, kind, eye, index);
}

int trm_dpi_view_shape(void* h, int* input_lines, int* input_samples, int* output_lines, int* output_samples) {
  trm_view_shape shape{};
  const trm_status status = trm_decoder_view_shape(h ? handle_of(h)->decoder : nullptr, &shape);
  *input_lines = shape.input_lines;
  *input_samples = shape.input_samples;
  *output_lines = shape.output_lines;
  *output_samples = shape.output_samples;
  return status;
}

// codes: the SystemVerilog line (int unsigned, 2-state), of which the first `samples` entries are sent.
int trm_dpi_push_line(void* h, const svOpenArrayHandle codes, int samples, int intact) {
  if (!h) return trm_decoder_push_line(nullptr, nullptr, 0, intact);
  Handle& handle = *handle_of(h);
  handle.error.clear();
  const int size = svSize(codes, 1);
  if (samples < 0 || samples > size) {
    handle.error = "push_line: " + std::to_string(samples) + " samples asked of a line array of " +
                   std::to_string(size);
    return TRM_ERROR_LINE_LENGTH;
  }
  handle.line.resize(static_cast<std::size_t>(samples));
  const int low = svLow(codes, 1);
  for (int i = 0; i < samples; ++i) {
    const auto word = *static_cast<const std::uint32_t*>(svGetArrElemPtr1(codes, low + i));
    // A word above 16 bits would wrap into a valid-looking code; the C API's own range check needs it whole.
    if (word > 0xffffu) {
      handle.error = "push_line: sample " + std::to_string(i) + " is " + std::to_string(word) +
                     ", above any link code";
      return TRM_ERROR_INVALID_CODE;
    }
    handle.line[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(word);
  }
  return trm_decoder_push_line(handle.decoder, handle.line.data(), handle.line.size(), intact);
}

int trm_dpi_end_view(void* h) {
  if (h) handle_of(h)->error.clear();
  return trm_decoder_end_view(h ? handle_of(h)->decoder : nullptr);
}

int trm_dpi_lines_ready(void* h, int* count) {
  int32_t ready = 0;
  const trm_status status = trm_decoder_lines_ready(h ? handle_of(h)->decoder : nullptr, &ready);
  *count = ready;
  return status;
}

// drive: filled with the row's drive codes (its size is the capacity); *samples gets the count written.
int trm_dpi_pop_line(void* h, int* row, const svOpenArrayHandle drive, int* samples) {
  *row = -1;
  *samples = 0;
  if (!h) return trm_decoder_pop_line(nullptr, nullptr, nullptr, 0, nullptr);
  Handle& handle = *handle_of(h);
  handle.error.clear();
  const int size = svSize(drive, 1);
  handle.line.resize(static_cast<std::size_t>(size));
  int32_t row_index = -1;
  std::size_t written = 0;
  const trm_status status =
      trm_decoder_pop_line(handle.decoder, &row_index, handle.line.data(), handle.line.size(), &written);
  if (status != TRM_OK) return status;
  const int low = svLow(drive, 1);
  for (std::size_t i = 0; i < written; ++i)
    *static_cast<std::uint32_t*>(svGetArrElemPtr1(drive, low + static_cast<int>(i))) = handle.line[i];
  *row = row_index;
  *samples = static_cast<int>(written);
  return status;
}

}  // extern "C"
