// The C API (trm/trm_c.h) over FixedStreamingDecoder's incremental form. Every entry point catches everything: a C
// caller (a DPI-C import, a SystemC module) sees a status and a message, never an exception.
#include "trm/trm_c.h"

#include "trm/decoder_json.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/panel.hpp"
#include "trm/resample.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <exception>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>

// The handle: the decoder, the view in flight and where popping has got to.
struct trm_decoder {
  explicit trm_decoder(trm::FixedDecoderConfig config) : decoder(std::move(config)) {}

  trm::FixedStreamingDecoder decoder;
  mutable std::string error;  // also set by the calls that only read the handle
  std::string text;             // the last JSON handed out (config or report)
  bool have_view = false;       // a view was begun (its shape is known)
  trm_view_shape shape{};
  trm::DecodedFrame ended;      // the last ended view: its rows are popped from here until the next begin
  bool view_ended = false;
  int next_pop = 0;
  trm::FixedStageCounts counts;
};

namespace {

thread_local std::string global_error;

// A failure with its status, thrown inside an entry point and turned into the return value at its boundary.
struct CError {
  trm_status status;
  std::string message;
};

[[noreturn]] void fail(trm_status status, std::string message) { throw CError{status, std::move(message)}; }

trm_status report_to(std::string& sink, trm_status status, std::string message) {
  sink = std::move(message);
  return status;
}

// Runs body for handle d, mapping every exception to a status and a message: CError as it says, an invalid argument
// of the C++ decoder to `invalid` (the entry point's meaning of a rejected input), the rest (the calls out of order
// are caught before the decoder sees them) to TRM_ERROR_INTERNAL.
template <typename Body>
trm_status guarded(const trm_decoder* d, const char* what, trm_status invalid, Body body) {
  if (d == nullptr) return report_to(global_error, TRM_ERROR_NULL_ARGUMENT, std::string(what) + ": null handle");
  std::string& sink = d->error;
  try {
    const trm_status status = body();
    if (status >= TRM_OK) sink.clear();
    return status;
  } catch (const CError& e) {
    return report_to(sink, e.status, std::string(what) + ": " + e.message);
  } catch (const std::invalid_argument& e) {
    return report_to(sink, invalid, std::string(what) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    return report_to(sink, TRM_ERROR_INTERNAL, std::string(what) + ": out of memory");
  } catch (const std::exception& e) {
    return report_to(sink, TRM_ERROR_INTERNAL, std::string(what) + ": " + e.what());
  } catch (...) {
    return report_to(sink, TRM_ERROR_INTERNAL, std::string(what) + ": unknown failure");
  }
}

void require(const void* pointer, const char* name) {
  if (pointer == nullptr) fail(TRM_ERROR_NULL_ARGUMENT, std::string(name) + " is null");
}

trm::FrameMeta view_meta(const trm_decoder& d, int32_t full_width, int32_t full_height, int32_t kind, int32_t eye,
                         int64_t index) {
  if (kind != TRM_FRAME_FULL && kind != TRM_FRAME_REDUCED) {
    fail(TRM_ERROR_INVALID_VIEW, "frame kind " + std::to_string(kind) + " is neither TRM_FRAME_FULL (0) nor "
                                 "TRM_FRAME_REDUCED (1)");
  }
  const trm::EncoderConfig& link = d.decoder.config().decoder.link;
  trm::FrameMeta meta;
  meta.index = index;
  meta.eye = eye;
  meta.parity = kind == TRM_FRAME_FULL ? trm::Parity::Full : trm::Parity::Reduced;
  meta.full_width = full_width;
  meta.full_height = full_height;
  // The size sent; a size the view cannot have is rejected by the decoder's view checks (check_view_meta) first.
  const bool sane = full_width > 0 && full_height > 0;
  meta.width = kind == TRM_FRAME_FULL || !sane ? full_width : trm::reduced_size(full_width, link.reduction);
  meta.height = kind == TRM_FRAME_FULL || !sane ? full_height : trm::reduced_size(full_height, link.reduction);
  meta.bits = link.bits;
  meta.transfer = link.transfer;
  return meta;
}

// A new view replaces what the last one left to pop.
void open_view(trm_decoder& d, const trm::FrameMeta& meta) {
  d.ended = trm::DecodedFrame();
  d.view_ended = false;
  d.next_pop = 0;
  d.have_view = true;
  d.shape.input_lines = meta.height;
  d.shape.input_samples = 3 * meta.width;
  d.shape.output_lines = meta.full_height;
  d.shape.output_samples = 3 * meta.full_width;
}

int rows_available(const trm_decoder& d) {
  if (d.view_ended) return d.ended.drive_codes.rows;
  return d.decoder.view_open() ? d.decoder.rows_ready() : 0;
}

trm_status create(trm::FixedDecoderConfig config, trm_decoder** out) {
  config.decoder.report_planes = false;  // the C API hands out drive codes and statistics only
  try {
    *out = new trm_decoder(std::move(config));  // validates the configuration
    global_error.clear();
    return TRM_OK;
  } catch (const std::invalid_argument& e) {
    return report_to(global_error, TRM_ERROR_INVALID_CONFIG, std::string("trm_decoder_create: ") + e.what());
  } catch (const std::bad_alloc&) {
    return report_to(global_error, TRM_ERROR_INTERNAL, "trm_decoder_create: out of memory");
  } catch (const std::exception& e) {
    return report_to(global_error, TRM_ERROR_INTERNAL, std::string("trm_decoder_create: ") + e.what());
  } catch (...) {
    return report_to(global_error, TRM_ERROR_INTERNAL, "trm_decoder_create: unknown failure");
  }
}

}  // namespace

extern "C" {

const char* trm_last_error(void) { return global_error.c_str(); }

const char* trm_decoder_last_error(const trm_decoder* d) { return d == nullptr ? trm_last_error() : d->error.c_str(); }

void trm_config_defaults(trm_config* config) {
  if (config == nullptr) return;
  const trm::FixedDecoderConfig defaults;  // allocates nothing (the panel name fits the string's own buffer)
  const trm::DecoderConfig& c = defaults.decoder;
  config->reduction = c.link.reduction;
  config->sigma = c.link.sigma;
  config->link_bits = c.link.bits;
  config->transfer = static_cast<int32_t>(c.link.transfer);
  config->resample_space = static_cast<int32_t>(c.link.resample_space);
  config->sensitivity = c.sensitivity;
  config->panel = nullptr;
  config->output_bits = c.output_bits;
  config->lcd_history = c.lcd_history == trm::LcdHistory::Wanted ? TRM_LCD_HISTORY_WANTED : TRM_LCD_HISTORY_CONTRIBUTED;
  config->skip_unneeded = defaults.skip_unneeded ? 1 : 0;
}

trm_status trm_decoder_create_json(const char* json, trm_decoder** out) {
  if (out == nullptr) return report_to(global_error, TRM_ERROR_NULL_ARGUMENT, "trm_decoder_create_json: out is null");
  *out = nullptr;
  if (json == nullptr) return report_to(global_error, TRM_ERROR_NULL_ARGUMENT, "trm_decoder_create_json: json is null");
  trm::FixedDecoderConfig config;
  try {
    const nlohmann::json parsed = nlohmann::json::parse(json);
    // A whole report (hw-report, vectors) carries the configuration as parameters.decoder.
    const bool report = parsed.is_object() && parsed.contains("parameters") && parsed["parameters"].is_object() &&
                        parsed["parameters"].contains("decoder");
    config = trm::fixed_decoder_config_from_json(report ? parsed["parameters"]["decoder"] : parsed);
  } catch (const nlohmann::json::exception& e) {
    return report_to(global_error, TRM_ERROR_INVALID_CONFIG, std::string("trm_decoder_create_json: ") + e.what());
  } catch (const std::invalid_argument& e) {
    return report_to(global_error, TRM_ERROR_INVALID_CONFIG, std::string("trm_decoder_create_json: ") + e.what());
  } catch (const std::bad_alloc&) {
    return report_to(global_error, TRM_ERROR_INTERNAL, "trm_decoder_create_json: out of memory");
  } catch (const std::exception& e) {
    return report_to(global_error, TRM_ERROR_INTERNAL, std::string("trm_decoder_create_json: ") + e.what());
  } catch (...) {
    return report_to(global_error, TRM_ERROR_INTERNAL, "trm_decoder_create_json: unknown failure");
  }
  return create(std::move(config), out);
}

trm_status trm_decoder_create(const trm_config* config, trm_decoder** out) {
  if (out == nullptr) return report_to(global_error, TRM_ERROR_NULL_ARGUMENT, "trm_decoder_create: out is null");
  *out = nullptr;
  if (config == nullptr) return report_to(global_error, TRM_ERROR_NULL_ARGUMENT, "trm_decoder_create: config is null");
  trm::FixedDecoderConfig c;
  try {
    trm::EncoderConfig& link = c.decoder.link;
    link.reduction = config->reduction;
    link.sigma = config->sigma;
    link.bits = config->link_bits;
    if (config->transfer != TRM_TRANSFER_SRGB && config->transfer != TRM_TRANSFER_GAMMA22) {
      throw std::invalid_argument("transfer " + std::to_string(config->transfer) +
                                  " is neither TRM_TRANSFER_SRGB (0) nor TRM_TRANSFER_GAMMA22 (1)");
    }
    link.transfer = static_cast<trm::Transfer>(config->transfer);
    if (config->resample_space != TRM_RESAMPLE_ENCODED && config->resample_space != TRM_RESAMPLE_LINEAR) {
      throw std::invalid_argument("resample space " + std::to_string(config->resample_space) +
                                  " is neither TRM_RESAMPLE_ENCODED (0) nor TRM_RESAMPLE_LINEAR (1)");
    }
    link.resample_space = static_cast<trm::ResampleSpace>(config->resample_space);
    c.decoder.sensitivity = config->sensitivity;
    if (config->panel != nullptr) c.decoder.panel = trm::parse_panel(config->panel);
    c.decoder.output_bits = config->output_bits;
    if (config->lcd_history != TRM_LCD_HISTORY_WANTED && config->lcd_history != TRM_LCD_HISTORY_CONTRIBUTED) {
      throw std::invalid_argument("lcd_history " + std::to_string(config->lcd_history) +
                                  " is neither TRM_LCD_HISTORY_WANTED (0) nor TRM_LCD_HISTORY_CONTRIBUTED (1)");
    }
    c.decoder.lcd_history =
        config->lcd_history == TRM_LCD_HISTORY_WANTED ? trm::LcdHistory::Wanted : trm::LcdHistory::Contributed;
    c.skip_unneeded = config->skip_unneeded != 0;
  } catch (const std::invalid_argument& e) {
    return report_to(global_error, TRM_ERROR_INVALID_CONFIG, std::string("trm_decoder_create: ") + e.what());
  } catch (...) {
    return report_to(global_error, TRM_ERROR_INTERNAL, "trm_decoder_create: unknown failure");
  }
  return create(std::move(c), out);
}

void trm_decoder_destroy(trm_decoder* d) { delete d; }

trm_status trm_decoder_config_json(trm_decoder* d, const char** json) {
  return guarded(d, "trm_decoder_config_json", TRM_ERROR_INTERNAL, [&] {
    require(json, "json");
    d->text = trm::fixed_decoder_json(d->decoder.config()).dump(2);
    *json = d->text.c_str();
    return TRM_OK;
  });
}

trm_status trm_decoder_begin_view(trm_decoder* d, int32_t full_width, int32_t full_height, int32_t kind, int32_t eye,
                                  int64_t index) {
  return guarded(d, "trm_decoder_begin_view", TRM_ERROR_INVALID_VIEW, [&] {
    if (d->decoder.view_open()) {
      fail(TRM_ERROR_VIEW_OPEN, "a view is still open (" + std::to_string(d->decoder.lines_pushed()) + " of " +
                                    std::to_string(d->shape.input_lines) + " lines pushed); end it first");
    }
    const trm::FrameMeta meta = view_meta(*d, full_width, full_height, kind, eye, index);
    d->decoder.begin_view(meta);
    open_view(*d, meta);
    return TRM_OK;
  });
}

trm_status trm_decoder_view_shape(const trm_decoder* d, trm_view_shape* shape) {
  return guarded(d, "trm_decoder_view_shape", TRM_ERROR_INTERNAL, [&] {
    require(shape, "shape");
    if (!d->have_view) fail(TRM_ERROR_NO_VIEW, "no view has been begun");
    *shape = d->shape;
    return TRM_OK;
  });
}

trm_status trm_decoder_push_line(trm_decoder* d, const uint16_t* codes, size_t samples, int32_t intact) {
  return guarded(d, "trm_decoder_push_line", TRM_ERROR_INVALID_CODE, [&] {
    if (!d->decoder.view_open()) {
      fail(TRM_ERROR_NO_VIEW, d->view_ended ? "a line pushed after the end of the view (begin the next view first)"
                                            : "a line pushed without an open view (begin one first)");
    }
    const int line = d->decoder.lines_pushed();
    if (line >= d->shape.input_lines) {
      fail(TRM_ERROR_TOO_MANY_LINES, "the view already has all its " + std::to_string(d->shape.input_lines) +
                                         " lines (end it with trm_decoder_end_view)");
    }
    if (intact != 0) {
      require(codes, "codes of an intact line");
      if (samples != static_cast<size_t>(d->shape.input_samples)) {
        fail(TRM_ERROR_LINE_LENGTH, "line " + std::to_string(line) + " has " + std::to_string(samples) +
                                        " samples but the view's input lines have " +
                                        std::to_string(d->shape.input_samples) + " (3 x " +
                                        std::to_string(d->shape.input_samples / 3) + " pixels, R G B interleaved)");
      }
    }
    // A code beyond the link depth is the only invalid argument left for the decoder to find.
    d->decoder.push_line(std::span<const std::uint16_t>(codes, intact != 0 ? samples : 0), intact != 0);
    return TRM_OK;
  });
}

trm_status trm_decoder_lines_ready(const trm_decoder* d, int32_t* count) {
  return guarded(d, "trm_decoder_lines_ready", TRM_ERROR_INTERNAL, [&] {
    require(count, "count");
    *count = rows_available(*d) - d->next_pop;
    return TRM_OK;
  });
}

trm_status trm_decoder_pop_line(trm_decoder* d, int32_t* row, uint16_t* drive, size_t capacity, size_t* samples) {
  return guarded(d, "trm_decoder_pop_line", TRM_ERROR_INTERNAL, [&] {
    require(row, "row");
    require(drive, "drive");
    if (d->next_pop >= rows_available(*d)) return TRM_NO_LINE;
    const size_t needed = static_cast<size_t>(d->shape.output_samples);
    if (samples != nullptr) *samples = needed;
    if (capacity < needed) {
      fail(TRM_ERROR_BUFFER_TOO_SMALL, "row " + std::to_string(d->next_pop) + " has " + std::to_string(needed) +
                                           " samples but the buffer holds " + std::to_string(capacity) +
                                           " (the row stays queued)");
    }
    const int y = d->next_pop;
    const std::uint16_t* source = d->view_ended ? d->ended.drive_codes.ptr<std::uint16_t>(y)
                                                : d->decoder.drive_row(y).data();
    std::copy(source, source + needed, drive);
    *row = y;
    ++d->next_pop;
    return TRM_OK;
  });
}

trm_status trm_decoder_end_view(trm_decoder* d) {
  return guarded(d, "trm_decoder_end_view", TRM_ERROR_INTERNAL, [&] {
    if (!d->decoder.view_open()) {
      fail(TRM_ERROR_NO_VIEW, d->view_ended ? "the view has already ended" : "no view is open");
    }
    if (d->decoder.lines_pushed() != d->shape.input_lines) {
      fail(TRM_ERROR_VIEW_INCOMPLETE, "only " + std::to_string(d->decoder.lines_pushed()) + " of the view's " +
                                          std::to_string(d->shape.input_lines) +
                                          " lines were pushed (push the rest, as lost lines if need be)");
    }
    d->ended = d->decoder.end_view();
    d->view_ended = true;
    d->counts = d->decoder.last_counts();
    return TRM_OK;
  });
}

trm_status trm_decoder_lost_view(trm_decoder* d, int32_t full_width, int32_t full_height, int32_t kind, int32_t eye,
                                 int64_t index) {
  return guarded(d, "trm_decoder_lost_view", TRM_ERROR_INVALID_VIEW, [&] {
    if (d->decoder.view_open()) {
      fail(TRM_ERROR_VIEW_OPEN, "a view is still open (" + std::to_string(d->decoder.lines_pushed()) + " of " +
                                    std::to_string(d->shape.input_lines) + " lines pushed); end it first");
    }
    const trm::FrameMeta meta = view_meta(*d, full_width, full_height, kind, eye, index);
    trm::DecodedFrame held = d->decoder.decode_lost(meta);
    open_view(*d, meta);
    d->ended = std::move(held);
    d->view_ended = true;
    d->counts = d->decoder.last_counts();
    return TRM_OK;
  });
}

trm_status trm_decoder_stage_counts(const trm_decoder* d, trm_stage_counts* counts) {
  return guarded(d, "trm_decoder_stage_counts", TRM_ERROR_INTERNAL, [&] {
    require(counts, "counts");
    const trm::FixedStageCounts& c = d->counts;
    counts->beta_clipped = c.beta_clipped;
    counts->residual_saturated = c.residual_saturated;
    counts->residual_rounded = c.residual_rounded;
    counts->alpha_clipped = c.alpha_clipped;
    counts->weight_underflow = c.weight_underflow;
    counts->lcd_unreachable = c.lcd_unreachable;
    counts->motion_test_lines_skipped = c.motion_test_lines_skipped;
    counts->residual_read_lines_skipped = c.residual_read_lines_skipped;
    counts->residual_write_lines_skipped = c.residual_write_lines_skipped;
    return TRM_OK;
  });
}

trm_status trm_decoder_report_json(trm_decoder* d, int32_t full_width, int32_t full_height, const char** json) {
  return guarded(d, "trm_decoder_report_json", TRM_ERROR_INVALID_VIEW, [&] {
    require(json, "json");
    trm::FrameMeta meta = view_meta(*d, full_width, full_height, TRM_FRAME_FULL, 0, 0);
    trm::check_view_meta(meta, "view " + std::to_string(full_width) + "x" + std::to_string(full_height) + ": ");
    const cv::Size full(full_width, full_height);
    d->text = trm::hw_report_json(d->decoder.config(), full, d->decoder.report(full)).dump(2);
    *json = d->text.c_str();
    return TRM_OK;
  });
}

}  // extern "C"
