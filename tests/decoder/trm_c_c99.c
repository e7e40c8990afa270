/* The C API used from C: compiled as C99 with -pedantic-errors (tests/decoder/CMakeLists.txt), so trm_c.h is proven
 * to be plain C. The C++ tests (trm_c_test.cpp) call c99_decode_views and compare its rows with the C++ decoder. */
#include "trm_c_c99.h"

#include "trm/trm_c.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Pops every ready row into out (rows of shape->output_samples); returns 0 or the failing status. */
static int pop_ready(trm_decoder* d, const trm_view_shape* shape, uint16_t* out, int32_t* next_row) {
  for (;;) {
    int32_t row = -1;
    size_t samples = 0;
    const trm_status s = trm_decoder_pop_line(d, &row, out + (size_t)(*next_row) * (size_t)shape->output_samples,
                                              (size_t)shape->output_samples, &samples);
    if (s == TRM_NO_LINE) return 0;
    if (s != TRM_OK) return (int)s;
    /* Raster order, each row once. */
    if (row != *next_row || samples != (size_t)shape->output_samples) return 100;
    ++*next_row;
  }
}

int c99_decode_views(const char* json, int32_t full_width, int32_t full_height, int32_t views,
                     const int32_t* kinds, const int32_t* eyes, const int64_t* indices, const uint16_t* const* codes,
                     const uint8_t* const* intact, uint16_t* drive, char* message, size_t message_capacity) {
  trm_decoder* d = NULL;
  int32_t v;
  int result = 0;
  trm_status s;
  if (message_capacity > 0) message[0] = '\0';
  if (json != NULL) {
    s = trm_decoder_create_json(json, &d);
  } else {
    trm_config config;
    trm_config_defaults(&config);
    s = trm_decoder_create(&config, &d);
  }
  if (s != TRM_OK) {
    if (message_capacity > 0) {
      strncpy(message, trm_last_error(), message_capacity - 1);
      message[message_capacity - 1] = '\0';
    }
    return (int)s;
  }
  for (v = 0; v < views && result == 0; ++v) {
    trm_view_shape shape;
    int32_t y;
    int32_t next_row = 0;
    const uint16_t* lines = codes[v];
    uint16_t* out = drive + (size_t)v * (size_t)full_width * 3u * (size_t)full_height;
    if ((s = trm_decoder_begin_view(d, full_width, full_height, kinds[v], eyes[v], indices[v])) != TRM_OK ||
        (s = trm_decoder_view_shape(d, &shape)) != TRM_OK) {
      result = (int)s;
      break;
    }
    for (y = 0; y < shape.input_lines && result == 0; ++y) {
      const int32_t line_intact = intact == NULL || intact[v] == NULL ? 1 : intact[v][y];
      s = trm_decoder_push_line(d, lines + (size_t)y * (size_t)shape.input_samples, (size_t)shape.input_samples,
                                line_intact);
      result = s != TRM_OK ? (int)s : pop_ready(d, &shape, out, &next_row);
    }
    if (result == 0) result = (s = trm_decoder_end_view(d)) != TRM_OK ? (int)s : pop_ready(d, &shape, out, &next_row);
    if (result == 0 && next_row != shape.output_lines) result = 101;
  }
  if (result != 0 && message_capacity > 0) {
    strncpy(message, trm_decoder_last_error(d), message_capacity - 1);
    message[message_capacity - 1] = '\0';
  }
  if (result == 0) {
    trm_stage_counts counts;
    const char* report = NULL;
    if (trm_decoder_stage_counts(d, &counts) != TRM_OK || trm_decoder_report_json(d, full_width, full_height,
                                                                                  &report) != TRM_OK ||
        report == NULL || report[0] != '{') {
      result = 102;
    }
  }
  trm_decoder_destroy(d);
  return result;
}
