// Streaming schedule of the fixed-point decoder (DESIGN §5): raster order, one input line at a time, through
// explicit circular line buffers and frame stores. The per-pixel arithmetic is the shared one (fixed_kernels.hpp),
// so this file only decides WHEN each line is computed and WHERE its inputs are held.
//
// Full frame, after each input line E_t(y_in):
//   1. the line enters the delay buffer (full width, link codes; I_t needs it when output row y_in is produced) and
//      its horizontal D pass enters the vertical Gaussian buffer (reduced width, uQb.L, at most 2R + 1 lines);
//   2. repeatedly: every output row whose U rows i0, i1 of d_t exist is produced; then the next reduced row of d_t
//      is produced if all its vertical taps have arrived (it enters the 2-line U buffer and the d_t frame store).
// Reduced frame, after each input line i(k): it enters the 2-line U buffer and every output row with i1 <= k is
// produced. The residual and d_{t-1} frame stores are read row by row.
#include "fixed_core.hpp"
#include "line_ring.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace trm {

using fixed_detail::FixedDecoderCore;
using fixed_detail::LineRing;
using fixed_detail::Geometry;
using fixed_detail::Raw;

namespace {

// The full-frame schedule as callbacks: on_input(y_in), on_reduced(k, y_in), on_output(y, y_in, reduced_ready).
// Nothing is produced before input line `first` (concealment: lost lines above the first intact line take that
// line's content, so work that needs them waits for it; 0 normally).
template <typename OnInput, typename OnReduced, typename OnOutput>
void full_frame_schedule(const Geometry& g, OnInput on_input, OnReduced on_reduced, OnOutput on_output, int first = 0) {
  int next_reduced = 0;
  int next_output = 0;
  for (int y_in = 0; y_in < g.full.height; ++y_in) {
    on_input(y_in);
    if (y_in < first) continue;
    for (;;) {
      while (next_output < g.full.height && next_output <= y_in &&
             g.bilinear_rows[static_cast<std::size_t>(next_output)].i1 < next_reduced) {
        on_output(next_output++, y_in, next_reduced);
      }
      if (next_reduced < g.reduced.height && g.gauss_rows[static_cast<std::size_t>(next_reduced)].last() <= y_in) {
        on_reduced(next_reduced++, y_in);
      } else {
        break;
      }
    }
  }
}

// The reduced-frame schedule: on_input(k), on_output(y, k); nothing is produced before input line `first`.
template <typename OnInput, typename OnOutput>
void reduced_frame_schedule(const Geometry& g, OnInput on_input, OnOutput on_output, int first = 0) {
  int next_output = 0;
  for (int k = 0; k < g.reduced.height; ++k) {
    on_input(k);
    if (k < first) continue;
    while (next_output < g.full.height && g.bilinear_rows[static_cast<std::size_t>(next_output)].i1 <= k) {
      on_output(next_output++, k);
    }
  }
}

// Line counts the schedules need, from a dry run over the indices.
struct StreamPlan {
  int gauss_lines = 0;     // vertical Gaussian buffer
  int delay_lines = 0;     // full-width delay of E_t for I_t
  int low_lines = 0;       // U buffer of d_t (full frames)
  int reduced_lines = 0;   // U buffer of i (reduced frames)
  int full_latency = 0;
  int reduced_latency = 0;
};

StreamPlan plan_for(const Geometry& g) {
  StreamPlan p;
  full_frame_schedule(
      g, [](int) {},
      [&](int k, int y_in) {
        p.gauss_lines = std::max(p.gauss_lines, y_in - g.gauss_rows[static_cast<std::size_t>(k)].first() + 1);
      },
      [&](int y, int y_in, int ready) {
        p.delay_lines = std::max(p.delay_lines, y_in - y + 1);
        p.full_latency = std::max(p.full_latency, y_in - y);
        p.low_lines = std::max(p.low_lines, ready - g.bilinear_rows[static_cast<std::size_t>(y)].i0);
      });
  reduced_frame_schedule(
      g, [](int) {},
      [&](int y, int k) {
        const int i0 = g.bilinear_rows[static_cast<std::size_t>(y)].i0;
        p.reduced_lines = std::max(p.reduced_lines, k - i0 + 1);
        p.reduced_latency = std::max(p.reduced_latency, k - i0);
      });
  return p;
}

}  // namespace

FixedStreamingDecoder::FixedStreamingDecoder(FixedDecoderConfig config)
    : core_(std::make_unique<FixedDecoderCore>(std::move(config))) {}
FixedStreamingDecoder::~FixedStreamingDecoder() = default;
FixedStreamingDecoder::FixedStreamingDecoder(FixedStreamingDecoder&&) noexcept = default;
FixedStreamingDecoder& FixedStreamingDecoder::operator=(FixedStreamingDecoder&&) noexcept = default;
const FixedDecoderConfig& FixedStreamingDecoder::config() const { return core_->config(); }
const FixedStageCounts& FixedStreamingDecoder::last_counts() const { return core_->last_counts(); }

FixedStreamingReport FixedStreamingDecoder::report(cv::Size full) const {
  const Geometry& g = core_->kernels().geometry(full);
  const StreamPlan p = plan_for(g);
  const FixedDecoderConfig& c = core_->config();
  const int b = c.decoder.link.bits;
  FixedStreamingReport r;
  r.full_latency_lines = p.full_latency;
  r.reduced_latency_lines = p.reduced_latency;
  r.full = g.full;
  r.reduced = g.reduced;
  r.roms = core_->kernels().roms();
  r.arithmetic = core_->kernels().arithmetic(g);
  // The linear resample space keeps D's horizontal results as linear light (uQ1.P). d_t is b-bit link codes in both.
  const bool linear = c.decoder.link.resample_space == ResampleSpace::Linear;
  const int gauss_bits = linear ? 1 + c.linear_resample_frac_bits : b + c.gaussian_line_frac_bits;
  const int low_bits = b;
  r.buffers = {
      {linear ? "line: vertical Gaussian (horizontal D results, linear uQ1." +
                    std::to_string(c.linear_resample_frac_bits) + ")"
              : std::string("line: vertical Gaussian (horizontal D results, uQb.L)"),
       p.gauss_lines, 3 * g.reduced.width, gauss_bits},
      {"line: E_t delay for I_t (link codes)", p.delay_lines, 3 * g.full.width, b},
      {"line: U of d_t (full frames, codes)", p.low_lines, 3 * g.reduced.width, b},
      {"line: U of i (reduced frames, codes)", p.reduced_lines, 3 * g.reduced.width, b},
      {"frame: residual rho (" + c.residual.to_string() + ")", g.full.height, 3 * g.full.width, c.residual.width()},
      {"frame: d_t for the motion test (codes)", g.reduced.height, 3 * g.reduced.width, low_bits},
  };
  const std::int64_t full_samples = 3 * static_cast<std::int64_t>(g.full.width) * g.full.height;
  const std::int64_t reduced_samples = 3 * static_cast<std::int64_t>(g.reduced.width) * g.reduced.height;
  r.paper_frame_store_bits = full_samples * b + full_samples * c.residual.width();
  r.model_frame_store_bits = reduced_samples * low_bits + full_samples * c.residual.width();
  // Appended field by field: a braced temporary built from a literal trips GCC 12's false -Warray-bounds.
  const auto add_frame_store = [&r](std::string name, int lines, int samples, int bits) {
    FixedBufferReport& store = r.buffers.emplace_back();
    store.name = std::move(name);
    store.lines = lines;
    store.samples = samples;
    store.bits = bits;
  };
  const bool lcd = c.decoder.panel.has_history();
  if (lcd) {
    add_frame_store("frame: LCD v_{t-1} (drive codes; re-shown when a view is lost)", g.full.height,
                    3 * g.full.width, c.decoder.output_bits);
    add_frame_store(std::string("frame: LCD x_{t-1} (sQ3.").append(std::to_string(c.linear_frac_bits)).append(")"),
                    g.full.height, 3 * g.full.width, 3 + c.linear_frac_bits);
  } else {
    add_frame_store("frame: held output (drive codes, re-shown when a view is lost)", g.full.height,
                    3 * g.full.width, c.decoder.output_bits);
  }
  if (c.skip_unneeded) {
    // DESIGN §7 skips: the line comparator's static flag beside the U buffer of i, and one residual-nonzero
    // bit per full line (the only storage the skips add; OLED already keeps no LCD stores).
    add_frame_store("line: U of i comparator flag (static) vs d_{t-1}", p.reduced_lines, 1, 1);
    add_frame_store("frame: residual-nonzero line flags (rho write / read gate)", g.full.height, 1, 1);
    FixedArithmeticReport& compare = r.arithmetic.emplace_back();
    compare.stage = "line comparator i vs d_{t-1} (static skip)";
    compare.frame = "reduced";
    compare.evaluated_per = "reduced sample";
    compare.evaluations = reduced_samples;
    compare.comparators = low_bits == b ? 1 : 2;
    FixedArithmeticReport& nonzero = r.arithmetic.emplace_back();
    nonzero.stage = "residual-nonzero OR (residual skip)";
    nonzero.frame = "full";
    nonzero.evaluated_per = "channel sample";
    nonzero.evaluations = full_samples;
    nonzero.comparators = 1;
  }
  r.concealment = std::string(
      "lost lines are replaced as they arrive, without extra line buffers: a lost line below an intact one repeats "
      "the concealed line above it from the input ring (E_t delay on full frames, U of i on reduced frames); lost "
      "lines above the first intact line of a view are read as that line (a replicate border moved down to it), so "
      "the output of such a view starts up to that many lines later than the latency above; a lost line of a "
      "reduced frame after its full frame takes the d_t frame store's row (one extra row read). A lost view "
      "re-shows the previous drive codes: ").append(
      lcd ? "the LCD v_{t-1} frame store already holds them."
          : "an OLED panel fed in raster order needs the held-output frame store listed above (not needed with a "
            "panel that keeps its own frame memory).");
  return r;
}

DecodedFrame FixedStreamingDecoder::decode(const LinkFrame& frame) { return decode_impl(frame, nullptr); }

DecodedFrame FixedStreamingDecoder::decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  detail::Concealment lost;
  switch (core_->classify(frame, line_intact, lost, "FixedStreamingDecoder")) {
    case detail::Arrival::Whole: return decode_impl(frame, nullptr);
    case detail::Arrival::Lost: return core_->decode_lost(frame.meta, "FixedStreamingDecoder");
    case detail::Arrival::Partial: break;
  }
  return decode_impl(frame, &lost);
}

DecodedFrame FixedStreamingDecoder::decode_lost(const FrameMeta& meta) {
  return core_->decode_lost(meta, "FixedStreamingDecoder");
}

namespace {

// Copies a line within a ring (a lost line takes the concealed line above it); with a one-line ring the two are the
// same slot and the line simply stays.
template <typename T>
void repeat_line(LineRing<T>& ring, int line, int samples) {
  const T* above = ring.read(line - 1);
  T* slot = ring.write(line);
  if (slot != above) std::copy(above, above + samples, slot);
}

}  // namespace

// Concealment in raster order (the reference's rules, line by line as the lines arrive):
//   * a lost line below an intact one repeats the line just above it, which the input ring (E_t delay or U of i)
//     still holds already concealed: by induction that is the nearest intact line above. No storage is added.
//   * lost lines above the first intact line of the view (nothing intact above them) are copies of that line (the
//     nearest intact line below): no data is kept for them, and every read of such a line reads the first intact
//     line instead, like a replicate border moved down to it. Work that needs them waits for that line, so such a
//     view's output starts up to first_intact lines later than normal.
//   * a lost line of a reduced frame with a stored d_{t-1} takes that frame store's row (an extra row read).
// Lost lines of a full frame then show L_t (full_pixel), as in the frame-at-a-time schedule.
DecodedFrame FixedStreamingDecoder::decode_impl(const LinkFrame& frame, const detail::Concealment* lost) {
  fixed_detail::EyeState& eye = core_->begin(frame, "FixedStreamingDecoder");
  fixed_detail::FixedKernels& kernels = core_->kernels();
  const Geometry& g = kernels.geometry(eye.full_size);
  const StreamPlan plan = plan_for(g);
  fixed_detail::FrameOutput out = core_->start_output(frame, eye);
  out.full = frame.meta.parity == Parity::Full;
  out.concealed_lines = lost != nullptr ? lost->lost_lines : 0;
  core_->begin_lcd(out, eye);
  const int full_samples = 3 * g.full.width;
  const int reduced_samples = 3 * g.reduced.width;
  const auto is_lost = [lost](int line) { return lost != nullptr && lost->lost(line); };
  // Lines above the first intact line read as the first intact line.
  const int first = lost != nullptr && lost->substitute.empty() ? lost->first_intact : 0;
  const auto source_line = [first](int line) { return std::max(line, first); };

  if (frame.meta.parity == Parity::Full) {
    LineRing<std::uint16_t> delay("E_t delay", plan.delay_lines, full_samples);
    LineRing<Raw> gauss("vertical Gaussian", plan.gauss_lines, reduced_samples);
    LineRing<std::uint16_t> low_lines("U of d_t", plan.low_lines, reduced_samples);
    cv::Mat residual_store = fixed_detail::reusable_plane(eye.spare_planes, g.full, CV_32SC3);  // frame store rho
    cv::Mat low_store = fixed_detail::reusable_plane(eye.spare_planes, g.reduced, CV_16UC3);    // frame store d_t
    std::vector<const Raw*> tap_rows;

    full_frame_schedule(
        g,
        [&](int y_in) {
          if (y_in < first) return;  // lost, nothing intact above: filled from line `first` when it arrives
          if (is_lost(y_in)) {
            repeat_line(delay, y_in, full_samples);
          } else {
            const std::uint16_t* received = frame.codes.ptr<std::uint16_t>(y_in);
            std::copy(received, received + full_samples, delay.write(y_in));
          }
          const std::uint16_t* in = delay.read(y_in);
          Raw* h = gauss.write(y_in);
          for (int k = 0; k < g.reduced.width; ++k) {
            for (int ch = 0; ch < 3; ++ch) {
              h[3 * k + ch] = kernels.gaussian_horizontal(in, g.gauss_cols[static_cast<std::size_t>(k)], ch);
            }
          }
        },
        [&](int k, int) {
          const fixed_detail::PolyphaseTaps& taps = g.gauss_rows[static_cast<std::size_t>(k)];
          tap_rows.clear();
          for (int index : taps.index) tap_rows.push_back(gauss.read(source_line(index)));
          std::uint16_t* d = low_lines.write(k);
          std::uint16_t* stored = low_store.ptr<std::uint16_t>(k);
          for (int i = 0; i < reduced_samples; ++i) {
            stored[i] = kernels.gaussian_vertical(tap_rows.data(), taps, i);
            d[i] = stored[i];
          }
        },
        [&](int y, int, int) {
          const fixed_detail::BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
          const std::uint16_t* codes_row = delay.read(source_line(y));
          const std::uint16_t* low0 = low_lines.read(row.i0);
          const std::uint16_t* low1 = low_lines.read(row.i1);
          std::int32_t* residual_row = residual_store.ptr<std::int32_t>(y);
          const bool lost_line = is_lost(y);
          for (int x = 0; x < g.full.width; ++x) {
            core_->full_pixel(out, eye, g, y, x, codes_row, low0, low1, residual_row, lost_line);
          }
          core_->end_full_line(out, eye, y, residual_row);
        },
        first);
    eye.have_residual = true;
    eye.residual_index = frame.meta.index;
    eye.residual = residual_store;
    eye.previous_low = low_store;
    return core_->finish(std::move(out), eye, true, false);
  }

  // frame.meta.index >= 0 (checked by begin), so index - 1 cannot overflow.
  const bool residual_applies = eye.have_residual && eye.residual_index == frame.meta.index - 1;
  LineRing<std::uint16_t> in_lines("U of i", plan.reduced_lines, reduced_samples);
  // DESIGN §7 static skip: the line comparator's result for each line held in the U buffer (2 bits per line).
  const bool gated = residual_applies && core_->skipping();
  LineRing<std::uint8_t> line_flags("U of i comparator flags", plan.reduced_lines, 1);
  reduced_frame_schedule(
      g,
      [&](int k) {
        if (k < first) return;
        if (!is_lost(k)) {
          const std::uint16_t* in = frame.codes.ptr<std::uint16_t>(k);
          std::copy(in, in + reduced_samples, in_lines.write(k));
        } else if (!lost->substitute.empty()) {
          const std::uint16_t* stored = lost->substitute.ptr<std::uint16_t>(k);  // d_{t-1} frame store row k
          std::copy(stored, stored + reduced_samples, in_lines.write(k));
        } else {
          repeat_line(in_lines, k, reduced_samples);
        }
        if (gated) {  // compared as the line enters the U buffer, against the d_{t-1} frame store row k
          *line_flags.write(k) = fixed_detail::FixedKernels::compare_line(eye.previous_low.ptr<std::uint16_t>(k),
                                                                          in_lines.read(k), reduced_samples);
        }
      },
      [&](int y, int) {
        const fixed_detail::BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
        const std::uint16_t* in0 = in_lines.read(source_line(row.i0));
        const std::uint16_t* in1 = in_lines.read(source_line(row.i1));
        fixed_detail::ReducedLineGate gate;
        if (gated) {
          // Lines above `first` (never held) do not skip.
          gate = core_->reduced_line_gate(out, eye, g, y, [&](int k) -> std::uint8_t {
            return k < first ? 0 : *line_flags.read(k);
          });
        }
        const bool read_previous = residual_applies && !gate.motion_static;
        const std::uint16_t* prev0 = read_previous ? eye.previous_low.ptr<std::uint16_t>(row.i0) : nullptr;
        const std::uint16_t* prev1 = read_previous ? eye.previous_low.ptr<std::uint16_t>(row.i1) : nullptr;
        const std::int32_t* residual_row =
            residual_applies && !gate.residual_zero ? eye.residual.ptr<std::int32_t>(y) : nullptr;
        for (int x = 0; x < g.full.width; ++x) {
          core_->reduced_pixel(out, eye, g, y, x, in0, in1, prev0, prev1, residual_row, gated ? &gate : nullptr);
        }
      },
      first);
  eye.have_residual = false;
  eye.residual.release();
  eye.previous_low.release();
  return core_->finish(std::move(out), eye, false, residual_applies);
}

}  // namespace trm
