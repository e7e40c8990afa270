// The bit-accurate streaming fixed-point decoder as a SystemC module, for virtual platforms: line-stream FIFO ports
// in and out, one output row per `clocks_per_row` clock cycles, the decoder itself behind the C API (trm/trm_c.h),
// so the module computes exactly the drive codes of `trm vectors` / `trm run`.
//
// Ports are sc_fifo channels of whole lines rather than a TLM-2.0 target socket: a display pipeline is a stream
// (one line after another, backpressure when the sink is full), which is what a bounded sc_fifo is; a TLM-2.0
// target is a memory-mapped slave (address, read/write, byte enables), the shape of a register file or a frame
// buffer, and would need an address convention for a stream that has none.
#pragma once

#include "trm/trm_c.h"

#include <systemc>

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace trm::sc {

// One line of the stream: an input line of link codes (the first line of a view carries its header) or an output
// row of drive codes. Samples interleaved R G B.
struct Line {
  bool first = false;       // input: first line of a view; the fields below describe the view
  int kind = TRM_FRAME_FULL;
  int eye = 0;
  std::int64_t index = 0;
  int full_width = 0;
  int full_height = 0;
  bool intact = true;       // input: false for a line lost on the link (samples are not read)
  int row = 0;              // output: row index in the view
  bool last = false;        // output: last row of the view
  std::vector<std::uint16_t> samples;

  bool operator==(const Line&) const = default;
};
// sc_fifo prints its contents through operator<< (sc_fifo::print, dump).
std::ostream& operator<<(std::ostream& out, const Line& line);

class DecoderModule : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk;
  sc_core::sc_fifo_in<Line> lines_in;
  sc_core::sc_fifo_out<Line> rows_out;

  // config_json: a fixed-point decoder configuration as the C API takes it (a `trm vectors` or `trm hw-report`
  // report.json, or its parameters.decoder). clocks_per_row >= 1: an output row is written at most every that many
  // clock cycles (the pixel pipeline's throughput); input lines are taken one per clock. Throws
  // std::invalid_argument with the C API's message for a configuration it rejects.
  DecoderModule(const sc_core::sc_module_name& name, const std::string& config_json, int clocks_per_row);
  ~DecoderModule() override;
  DecoderModule(const DecoderModule&) = delete;
  DecoderModule& operator=(const DecoderModule&) = delete;

  std::int64_t lines_taken() const { return lines_taken_; }
  std::int64_t rows_given() const { return rows_given_; }
  // The stage counters of the last ended view.
  trm_stage_counts last_counts() const;

 private:
  void take_lines();  // SC_THREAD: input lines into the decoder
  void give_rows();   // SC_THREAD: ready rows out, one per clocks_per_row clocks
  // A refused call stops the simulation with an SC_REPORT_ERROR naming the call and the decoder's message.
  void check(trm_status status, const char* call) const;

  trm_decoder* decoder_ = nullptr;
  int clocks_per_row_ = 1;
  trm_view_shape shape_{};
  int lines_pushed_ = 0;
  int rows_popped_ = 0;       // of the current view
  bool view_ended_ = true;
  sc_core::sc_event rows_ready_;  // a push or an end of view may have made rows ready
  sc_core::sc_event view_drained_;  // the last row of an ended view was popped
  std::int64_t lines_taken_ = 0;
  std::int64_t rows_given_ = 0;
};

}  // namespace trm::sc
