/* The bit-accurate streaming fixed-point decoder (trm::FixedStreamingDecoder) as a plain C99 API, line in and
 * line out, for the places a C++ class cannot go: an RTL testbench through DPI-C, a SystemC module, a scoreboard.
 *
 * One handle decodes a sequence of views the way the hardware sees them:
 *
 *   trm_decoder* d = NULL;
 *   if (trm_decoder_create_json(json_text, &d) != TRM_OK) fprintf(stderr, "%s\n", trm_last_error());
 *   trm_decoder_begin_view(d, 2160, 1200, TRM_FRAME_FULL, 0, t);      (full view size, kind, eye, index t)
 *   trm_view_shape shape;  trm_decoder_view_shape(d, &shape);         (input lines and samples per line)
 *   for (y = 0; y < shape.input_lines; ++y) {
 *     trm_decoder_push_line(d, line[y], shape.input_samples, 1);      (1 = intact, 0 = lost on the link)
 *     while (trm_decoder_pop_line(d, &row, drive, capacity, &n) == TRM_OK) check(row, drive, n);
 *   }
 *   trm_decoder_end_view(d);
 *   while (trm_decoder_pop_line(d, &row, drive, capacity, &n) == TRM_OK) check(row, drive, n);
 *   trm_decoder_destroy(d);
 *
 * Bits: the drive codes popped are exactly those of FixedStreamingDecoder::decode (and of FixedFrameDecoder and the
 * golden vectors), row for row. Rows come out in raster order, each once, as soon as the hardware schedule has
 * them: a full frame's row y after input line y or the last input line its vertical Gaussian taps need, whichever is
 * later; a reduced frame's row y after reduced input line i1(y), the lower of its two bilinear source rows. The
 * hardware report's latencies (trm_decoder_report_json: full_frame_latency_lines, reduced_frame_latency_lines) are
 * the largest of these delays over the rows, so row y is ready at the latest after input line
 * y + full_frame_latency_lines (full frames; clamped to the last line). Lost lines above the first intact line of
 * a view delay its output further (README "Concealment").
 *
 * Samples: a line is interleaved R G B, 3 * width uint16_t samples (link codes 0 .. 2^link_bits - 1 in; drive codes
 * 0 .. 2^output_bits - 1 out). An input line of a full frame is full width; of a reduced frame, reduced width (the
 * encoder's reduced size of the view, as trm_decoder_view_shape gives it). Output rows are full width.
 *
 * Errors: every function returns a trm_status, TRM_OK (0) on success. Nothing is thrown or aborted across this
 * boundary. On an error trm_decoder_last_error(d) says what went wrong (trm_last_error() for create failures and
 * null handles, per thread); the message stays valid until the next call on that handle (thread). A rejected call
 * changes nothing: a line that is refused is not taken, and the same view goes on with the next push. The only
 * exception is TRM_ERROR_INTERNAL (out of memory, a defect) in the middle of a view: that view is abandoned and the
 * next call must be trm_decoder_begin_view or trm_decoder_lost_view.
 *
 * Threads: one handle is used by one thread at a time; different handles are independent.
 */
#ifndef TRM_TRM_C_H
#define TRM_TRM_C_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Incremented when a signature or a struct below changes. */
#define TRM_C_API_VERSION 1

typedef enum trm_status {
  TRM_OK = 0,
  TRM_NO_LINE = 1,                 /* pop: no output row is ready (not an error; nothing is changed) */
  TRM_ERROR_NULL_ARGUMENT = -1,    /* a null handle or a null pointer where one is required */
  TRM_ERROR_INVALID_CONFIG = -2,   /* create: malformed JSON, a missing field, or a configuration the decoder rejects */
  TRM_ERROR_INVALID_VIEW = -3,     /* begin/lost view: size, kind, eye or index outside what the decoder accepts */
  TRM_ERROR_NO_VIEW = -4,          /* push or end without an open view (e.g. a line after end of view) */
  TRM_ERROR_VIEW_OPEN = -5,        /* begin or lost view while a view is still open */
  TRM_ERROR_LINE_LENGTH = -6,      /* push: sample count is not 3 x the input line width */
  TRM_ERROR_TOO_MANY_LINES = -7,   /* push: the view already has all its lines */
  TRM_ERROR_INVALID_CODE = -8,     /* push: a code beyond the link bit depth */
  TRM_ERROR_VIEW_INCOMPLETE = -9,  /* end: lines are still missing (push them, as lost lines if need be) */
  TRM_ERROR_BUFFER_TOO_SMALL = -10,/* pop / report: the caller's buffer cannot hold the result (nothing popped) */
  TRM_ERROR_INTERNAL = -11         /* out of memory or a defect; see the message */
} trm_status;

/* The kind of a view (Parity): a full frame carries the full-size view, a reduced frame the reduced one. */
enum { TRM_FRAME_FULL = 0, TRM_FRAME_REDUCED = 1 };
/* Link transfer function and resample space (trm::Transfer, trm::ResampleSpace). */
enum { TRM_TRANSFER_SRGB = 0, TRM_TRANSFER_GAMMA22 = 1 };
enum { TRM_RESAMPLE_ENCODED = 0, TRM_RESAMPLE_LINEAR = 1 };
/* LCD history rule (trm::LcdHistory). */
enum { TRM_LCD_HISTORY_WANTED = 0, TRM_LCD_HISTORY_CONTRIBUTED = 1 };

/* The common fields of a configuration; every fixed-point format keeps its default (FixedDecoderConfig). For full
 * control create from JSON instead. Fill with trm_config_defaults first, then change what differs. */
typedef struct trm_config {
  double reduction;        /* r in (0, 1] */
  double sigma;            /* Gaussian sigma of D; <= 0: the default for r */
  int32_t link_bits;       /* 8 or 10 */
  int32_t transfer;        /* TRM_TRANSFER_* */
  int32_t resample_space;  /* TRM_RESAMPLE_* */
  double sensitivity;      /* motion sensitivity s (Eq. 6), 0 .. 255 or INFINITY */
  const char* panel;       /* panel spec as `trm --panel` takes it: "vive", "rift", "generic", "gamma:G",
                              "gamma:GR,GG,GB", "lcd", "lcd:p1,p2,p3,p4,gamma"; NULL: the C++ default
                              (trm::Panel{}, OLED gamma 2.2). Read during create only. */
  int32_t output_bits;     /* drive code depth, 8 or 10 */
  int32_t lcd_history;     /* TRM_LCD_HISTORY_* */
  int32_t skip_unneeded;   /* nonzero: DESIGN section 7 skips (bit-identical output either way) */
} trm_config;

/* The shape of the open view, for sizing buffers. Samples are uint16_t counts (3 per pixel). */
typedef struct trm_view_shape {
  int32_t input_lines;     /* lines to push: full height, or reduced height for a reduced frame */
  int32_t input_samples;   /* samples per input line */
  int32_t output_lines;    /* rows to pop: the full view height */
  int32_t output_samples;  /* samples per output row: 3 x full width */
} trm_view_shape;

/* Per-stage event counters of the last ended view (trm::FixedStageCounts), in channel samples unless noted. */
typedef struct trm_stage_counts {
  uint64_t beta_clipped;
  uint64_t residual_saturated;
  uint64_t residual_rounded;
  uint64_t alpha_clipped;
  uint64_t weight_underflow;
  uint64_t lcd_unreachable;
  uint64_t motion_test_lines_skipped;     /* output lines */
  uint64_t residual_read_lines_skipped;   /* output lines */
  uint64_t residual_write_lines_skipped;  /* output lines */
} trm_stage_counts;

typedef struct trm_decoder trm_decoder;

/* The message of the last failed call of this thread that had no usable handle (create, null handle); "" if none. */
const char* trm_last_error(void);
/* The message of the last call on d if it failed, else "" (a successful call clears it); with d NULL,
 * trm_last_error(). */
const char* trm_decoder_last_error(const trm_decoder* d);

/* The C++ decoder's defaults (trm::FixedDecoderConfig{}): r = 0.5, sigma default, 8-bit sRGB link, encoded
 * resample space, s = 10, panel NULL, 8-bit drive, history wanted, skips on. */
void trm_config_defaults(trm_config* config);

/* Creates a decoder from a fixed-point decoder configuration as JSON text (NUL-terminated): the object reports carry
 * for it (trm::fixed_decoder_json: `parameters.decoder` of `trm hw-report` / `trm vectors` output), or such a whole
 * report, whose `parameters.decoder` is then taken. On failure *out is NULL and trm_last_error() names the field or
 * rule. */
trm_status trm_decoder_create_json(const char* json, trm_decoder** out);
/* Creates a decoder from the common fields (all formats at their defaults). */
trm_status trm_decoder_create(const trm_config* config, trm_decoder** out);
/* Frees the decoder (NULL is allowed and does nothing). */
void trm_decoder_destroy(trm_decoder* d);

/* The decoder's whole configuration as JSON (trm::fixed_decoder_json), owned by d, valid until the next call on d. */
trm_status trm_decoder_config_json(trm_decoder* d, const char** json);

/* Opens a view: the full view size (also for a reduced frame), TRM_FRAME_FULL / TRM_FRAME_REDUCED, eye (0 left or
 * mono, 1 right) and the view's index t (>= 0; a reduced view t uses the residual of full view t - 1 of the same
 * eye). Output rows of the previous view not yet popped are dropped. */
trm_status trm_decoder_begin_view(trm_decoder* d, int32_t full_width, int32_t full_height, int32_t kind, int32_t eye,
                                  int64_t index);
/* The shape of the open view (or of the last one, after it ended). */
trm_status trm_decoder_view_shape(const trm_decoder* d, trm_view_shape* shape);
/* Pushes the next input line of the open view. intact nonzero: codes holds `samples` link codes (samples must be
 * shape.input_samples). intact 0: the line was lost on the link and is concealed (as decode(frame, line_intact));
 * codes is not read and may be NULL, samples is ignored. */
trm_status trm_decoder_push_line(trm_decoder* d, const uint16_t* codes, size_t samples, int32_t intact);
/* The number of output rows ready to pop. */
trm_status trm_decoder_lines_ready(const trm_decoder* d, int32_t* count);
/* Pops the next ready output row: its index into *row and its drive codes into drive (capacity in samples), the
 * sample count written into *samples (may be NULL). TRM_NO_LINE when none is ready. TRM_ERROR_BUFFER_TOO_SMALL (the
 * row stays queued) when capacity < shape.output_samples. */
trm_status trm_decoder_pop_line(trm_decoder* d, int32_t* row, uint16_t* drive, size_t capacity, size_t* samples);
/* Ends the open view once all its lines are pushed: the frame stores (residual, d_t, LCD history, held output) and
 * the counters are final. A view whose lines were all lost shows the eye's previous output again (black if none):
 * its rows become ready here. */
trm_status trm_decoder_end_view(trm_decoder* d);
/* A view that never arrived at all (no line of it): the eye's previous output again, ready to pop at once; the
 * residual is dropped (trm::FixedStreamingDecoder::decode_lost). No view may be open. */
trm_status trm_decoder_lost_view(trm_decoder* d, int32_t full_width, int32_t full_height, int32_t kind, int32_t eye,
                                 int64_t index);

/* The stage counters of the last ended view. */
trm_status trm_decoder_stage_counts(const trm_decoder* d, trm_stage_counts* counts);
/* The hardware resource report for a view of the given full size as JSON, the document `trm hw-report` writes
 * ({"parameters": {"size", "decoder"}, "hardware": {latency, buffers, ROMs, arithmetic, totals, ...}}), owned by d,
 * valid until the next call on d. */
trm_status trm_decoder_report_json(trm_decoder* d, int32_t full_width, int32_t full_height, const char** json);

#ifdef __cplusplus
}
#endif

#endif /* TRM_TRM_C_H */
