#include "trm/systemc_decoder.hpp"

#include <ostream>
#include <stdexcept>
#include <string>

namespace trm::sc {

std::ostream& operator<<(std::ostream& out, const Line& line) {
  if (line.first)
    out << "view " << line.index << (line.kind == TRM_FRAME_FULL ? " full" : " reduced") << " eye " << line.eye
        << " " << line.full_width << "x" << line.full_height << ", ";
  return out << "row " << line.row << (line.last ? " (last)" : "") << (line.intact ? "" : " lost") << ", "
             << line.samples.size() << " samples";
}

DecoderModule::DecoderModule(const sc_core::sc_module_name& name, const std::string& config_json, int clocks_per_row)
    : sc_core::sc_module(name), clocks_per_row_(clocks_per_row) {
  if (clocks_per_row < 1)
    throw std::invalid_argument("trm::sc::DecoderModule: clocks_per_row must be >= 1, not " +
                                std::to_string(clocks_per_row));
  if (trm_decoder_create_json(config_json.c_str(), &decoder_) != TRM_OK)
    throw std::invalid_argument(std::string("trm::sc::DecoderModule: ") + trm_last_error());
  SC_HAS_PROCESS(DecoderModule);
  SC_THREAD(take_lines);
  SC_THREAD(give_rows);
}

DecoderModule::~DecoderModule() { trm_decoder_destroy(decoder_); }

trm_stage_counts DecoderModule::last_counts() const {
  trm_stage_counts counts{};
  check(trm_decoder_stage_counts(decoder_, &counts), "trm_decoder_stage_counts");
  return counts;
}

void DecoderModule::check(trm_status status, const char* call) const {
  if (status >= TRM_OK) return;
  const std::string message = std::string(name()) + ": " + call + " failed (" + std::to_string(status) +
                              "): " + trm_decoder_last_error(decoder_);
  SC_REPORT_ERROR("trm/decoder", message.c_str());
}

void DecoderModule::take_lines() {
  for (;;) {
    const Line line = lines_in.read();
    wait(clk.posedge_event());
    if (line.first) {
      // begin_view drops rows not yet popped: the previous view's rows must all be out first.
      while (!view_ended_ || rows_popped_ < shape_.output_lines) {
        if (!view_ended_) {
          const std::string message = std::string(name()) + ": a view began after " +
                                      std::to_string(lines_pushed_) + " of the previous view's " +
                                      std::to_string(shape_.input_lines) + " lines";
          SC_REPORT_ERROR("trm/decoder", message.c_str());
          return;
        }
        wait(view_drained_);
      }
      check(trm_decoder_begin_view(decoder_, line.full_width, line.full_height, line.kind, line.eye, line.index),
            "trm_decoder_begin_view");
      check(trm_decoder_view_shape(decoder_, &shape_), "trm_decoder_view_shape");
      lines_pushed_ = 0;
      rows_popped_ = 0;
      view_ended_ = false;
    } else if (view_ended_) {
      SC_REPORT_ERROR("trm/decoder", (std::string(name()) + ": a line outside a view (the first line of a view "
                                                             "carries first = true)").c_str());
      return;
    }
    check(trm_decoder_push_line(decoder_, line.samples.data(), line.samples.size(), line.intact ? 1 : 0),
          "trm_decoder_push_line");
    ++lines_pushed_;
    ++lines_taken_;
    if (lines_pushed_ == shape_.input_lines) {
      check(trm_decoder_end_view(decoder_), "trm_decoder_end_view");
      view_ended_ = true;
    }
    rows_ready_.notify(sc_core::SC_ZERO_TIME);
  }
}

void DecoderModule::give_rows() {
  for (;;) {
    int32_t ready = 0;
    check(trm_decoder_lines_ready(decoder_, &ready), "trm_decoder_lines_ready");
    if (ready == 0) {
      wait(rows_ready_);
      continue;
    }
    Line row;
    row.samples.resize(static_cast<std::size_t>(shape_.output_samples));
    size_t written = 0;
    int32_t index = 0;
    check(trm_decoder_pop_line(decoder_, &index, row.samples.data(), row.samples.size(), &written),
          "trm_decoder_pop_line");
    row.samples.resize(written);
    row.row = index;
    row.last = index == shape_.output_lines - 1;
    ++rows_popped_;
    if (view_ended_ && rows_popped_ == shape_.output_lines) view_drained_.notify(sc_core::SC_ZERO_TIME);
    rows_out.write(row);
    ++rows_given_;
    for (int i = 0; i < clocks_per_row_; ++i) wait(clk.posedge_event());
  }
}

}  // namespace trm::sc
