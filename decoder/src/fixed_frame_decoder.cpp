// Frame-at-a-time schedule of the fixed-point decoder: each stage runs over a whole frame before the next, as in
// the reference decoder, calling the shared per-pixel arithmetic (fixed_kernels.hpp).
#include "fixed_core.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace trm {

using fixed_detail::FixedDecoderCore;
using fixed_detail::Geometry;
using fixed_detail::Raw;

namespace {

// d_t = Q_b(D(E_t)) over the whole frame: the horizontal pass on every row, then the vertical pass; link codes as
// the d_t frame store holds them.
// Chroma skip (DESIGN §7): grey_rows[y] marks the grey input rows, whose horizontal pass runs on one channel; a row
// of d_t whose taps are all grey runs its vertical pass on one channel (reduced_row_grey records its flag).
cv::Mat reduce_whole_frame(const FixedDecoderCore& core, fixed_detail::FrameOutput& frame_out,
                           fixed_detail::EyeState& eye, const Geometry& g, const cv::Mat& codes,
                           const std::vector<std::uint8_t>& grey_rows) {
  const fixed_detail::FixedKernels& kernels = core.kernels();
  const int samples = 3 * g.reduced.width;
  std::vector<std::vector<Raw>> horizontal(static_cast<std::size_t>(g.full.height), std::vector<Raw>(static_cast<std::size_t>(samples)));
  for (int y = 0; y < g.full.height; ++y) {
    kernels.gaussian_horizontal_line(codes.ptr<std::uint16_t>(y), g, horizontal[static_cast<std::size_t>(y)].data(),
                                     grey_rows[static_cast<std::size_t>(y)] != 0);
  }
  cv::Mat low(g.reduced, CV_16UC3);
  std::vector<const Raw*> rows;
  for (int k = 0; k < g.reduced.height; ++k) {
    const fixed_detail::PolyphaseTaps& taps = g.gauss_rows[static_cast<std::size_t>(k)];
    rows.clear();
    for (int index : taps.index) rows.push_back(horizontal[static_cast<std::size_t>(index)].data());
    const bool grey = core.reduced_row_grey(frame_out, eye, g, k, true, [&](int line) {
      return grey_rows[static_cast<std::size_t>(line)] != 0;
    });
    kernels.gaussian_vertical_row(rows.data(), taps, samples, low.ptr<std::uint16_t>(k), grey);
  }
  return low;
}

// The grey detector of the chroma skip over every row of a frame of codes (all 0 when not skipping).
std::vector<std::uint8_t> grey_rows_of(const FixedDecoderCore& core, const cv::Mat& codes) {
  std::vector<std::uint8_t> grey(static_cast<std::size_t>(codes.rows), 0);
  if (!core.skipping()) return grey;
  for (int y = 0; y < codes.rows; ++y) {
    grey[static_cast<std::size_t>(y)] = fixed_detail::FixedKernels::grey_line(codes.ptr<std::uint16_t>(y), codes.cols) ? 1 : 0;
  }
  return grey;
}

// The static-skip line comparator (DESIGN §7) over every reduced row: row k of the received (concealed) codes against
// the stored d_{t-1} row k. Rows above the first intact line of a view without a d_{t-1} substitute are not compared
// (the streaming schedule never holds them), so they never skip.
std::vector<std::uint8_t> compare_lines(const cv::Mat& codes, const cv::Mat& previous_low,
                                        const detail::Concealment* lost) {
  const int first = lost != nullptr && lost->substitute.empty() ? lost->first_intact : 0;
  std::vector<std::uint8_t> flags(static_cast<std::size_t>(codes.rows), 0);
  for (int k = first; k < codes.rows; ++k) {
    flags[static_cast<std::size_t>(k)] = fixed_detail::FixedKernels::compare_line(
        previous_low.ptr<std::uint16_t>(k), codes.ptr<std::uint16_t>(k), 3 * codes.cols);
  }
  return flags;
}

}  // namespace

FixedFrameDecoder::FixedFrameDecoder(FixedDecoderConfig config)
    : core_(std::make_unique<FixedDecoderCore>(std::move(config))) {}
FixedFrameDecoder::~FixedFrameDecoder() = default;
FixedFrameDecoder::FixedFrameDecoder(FixedFrameDecoder&&) noexcept = default;
FixedFrameDecoder& FixedFrameDecoder::operator=(FixedFrameDecoder&&) noexcept = default;
const FixedDecoderConfig& FixedFrameDecoder::config() const { return core_->config(); }
const FixedStageCounts& FixedFrameDecoder::last_counts() const { return core_->last_counts(); }

DecodedFrame FixedFrameDecoder::decode(const LinkFrame& frame) { return decode_impl(frame, nullptr, nullptr); }

DecodedFrame FixedFrameDecoder::decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  detail::Concealment lost;
  switch (core_->classify(frame, line_intact, lost, "FixedFrameDecoder")) {
    case detail::Arrival::Whole: return decode_impl(frame, nullptr, nullptr);
    case detail::Arrival::Lost: return core_->decode_lost(frame.meta, "FixedFrameDecoder");
    case detail::Arrival::Partial: break;
  }
  return decode_impl(frame, nullptr, &lost);
}

DecodedFrame FixedFrameDecoder::decode_lost(const FrameMeta& meta) {
  return core_->decode_lost(meta, "FixedFrameDecoder");
}

DecodedFrame FixedFrameDecoder::decode(const LinkFrame& frame, FixedStageTaps& taps) {
  DecodedFrame decoded = decode_impl(frame, &taps, nullptr);
  // The planes held outside the per-pixel stages: received codes and drive codes.
  const auto copy_codes = [](const cv::Mat& m, FixedStagePlane& p) {
    for (int y = 0; y < m.rows; ++y) {
      const std::uint16_t* row = m.ptr<std::uint16_t>(y);
      std::copy(row, row + 3 * m.cols, p.values.begin() + static_cast<std::ptrdiff_t>(y) * 3 * m.cols);
    }
  };
  copy_codes(frame.codes, taps[Stage::Codes]);
  copy_codes(decoded.drive_codes, taps[Stage::Drive]);
  return decoded;
}

DecodedFrame FixedFrameDecoder::decode_impl(const LinkFrame& received, FixedStageTaps* taps,
                                            const detail::Concealment* lost) {
  fixed_detail::EyeState& eye = core_->begin(received, "FixedFrameDecoder");
  // Concealment: every lost line replaced first, then the view decoded as if it had arrived so.
  const LinkFrame frame = lost != nullptr ? LinkFrame{received.meta, detail::concealed_codes(received.codes, *lost)}
                                          : received;
  const Geometry& g = core_->kernels().geometry(eye.full_size);
  fixed_detail::FrameOutput out = core_->start_output(frame.meta, eye, true);  // begin checked every code
  out.full = frame.meta.parity == Parity::Full;
  out.concealed_lines = lost != nullptr ? lost->lost_lines : 0;
  core_->begin_lcd(out, eye);
  if (taps != nullptr) {
    core_->start_taps(out, *taps, g, out.full,
                      !out.full && eye.have_residual && eye.residual_index == frame.meta.index - 1);
  }
  const auto row_of = [](const cv::Mat& m, int y) { return m.ptr<std::uint16_t>(y); };
  fixed_detail::LineScratch scratch;

  const std::vector<std::uint8_t> grey_rows = grey_rows_of(*core_, frame.codes);
  if (frame.meta.parity == Parity::Full) {
    core_->start_full_lines(eye, g);
    const cv::Mat low = reduce_whole_frame(*core_, out, eye, g, frame.codes, grey_rows);  // d_t codes
    if (taps != nullptr) {
      std::vector<std::int64_t>& d = (*taps)[Stage::Reduced].values;
      for (int k = 0; k < low.rows; ++k) {
        const std::uint16_t* in = low.ptr<std::uint16_t>(k);
        std::copy(in, in + 3 * low.cols, d.begin() + static_cast<std::ptrdiff_t>(k) * 3 * low.cols);
      }
    }
    cv::Mat residual(g.full, CV_32SC3);
    const std::vector<std::uint8_t>& low_grey = eye.low_grey;  // the d_t rows' flags (empty when not skipping)
    const auto low_is_grey = [&](int k) { return !low_grey.empty() && low_grey[static_cast<std::size_t>(k)] != 0; };
    for (int y = 0; y < g.full.height; ++y) {
      const fixed_detail::BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
      const bool grey = core_->full_line_grey(out, grey_rows[static_cast<std::size_t>(y)] != 0, low_is_grey(row.i0),
                                              low_is_grey(row.i1));
      core_->full_line(out, eye, g, y, row_of(frame.codes, y), row_of(low, row.i0), row_of(low, row.i1),
                       residual.ptr<std::int32_t>(y), lost != nullptr && lost->lost(y), grey, scratch);
      core_->end_full_line(out, eye, y, residual.ptr<std::int32_t>(y), scratch);
    }
    eye.have_residual = true;
    eye.residual_index = frame.meta.index;
    eye.residual = residual;
    eye.previous_low = low;
    return core_->finish(std::move(out), eye, true, false);
  }

  // frame.meta.index >= 0 (checked by begin), so index - 1 cannot overflow.
  const bool residual_applies = eye.have_residual && eye.residual_index == frame.meta.index - 1;
  const bool gated = residual_applies && core_->skipping();
  const std::vector<std::uint8_t> line_flags = gated ? compare_lines(frame.codes, eye.previous_low, lost)
                                                     : std::vector<std::uint8_t>();
  for (int y = 0; y < g.full.height; ++y) {
    const fixed_detail::BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
    const auto grey_of = [&](const fixed_detail::ReducedLineGate& gate) {
      return core_->reduced_line_grey(out, eye, g, y, grey_rows[static_cast<std::size_t>(row.i0)] != 0,
                                      grey_rows[static_cast<std::size_t>(row.i1)] != 0, residual_applies, gate);
    };
    if (gated) {
      const fixed_detail::ReducedLineGate gate = core_->reduced_line_gate(
          out, eye, g, y, [&](int k) { return line_flags[static_cast<std::size_t>(k)]; });
      const bool read_previous = gate.reads_previous();
      const bool grey = grey_of(gate);
      core_->reduced_line(out, eye, g, y, row_of(frame.codes, row.i0), row_of(frame.codes, row.i1),
                          read_previous ? row_of(eye.previous_low, row.i0) : nullptr,
                          read_previous ? row_of(eye.previous_low, row.i1) : nullptr,
                          gate.residual_zero ? nullptr : eye.residual.ptr<std::int32_t>(y), &gate, grey, scratch);
      continue;
    }
    const bool grey = grey_of(fixed_detail::ReducedLineGate{});
    if (residual_applies) {
      core_->reduced_line(out, eye, g, y, row_of(frame.codes, row.i0), row_of(frame.codes, row.i1),
                          row_of(eye.previous_low, row.i0), row_of(eye.previous_low, row.i1),
                          eye.residual.ptr<std::int32_t>(y), nullptr, grey, scratch);
    } else {
      core_->reduced_line(out, eye, g, y, row_of(frame.codes, row.i0), row_of(frame.codes, row.i1), nullptr, nullptr,
                          nullptr, nullptr, grey, scratch);
    }
  }
  // The residual serves exactly one reduced frame.
  eye.have_residual = false;
  eye.residual.release();
  eye.previous_low.release();
  return core_->finish(std::move(out), eye, false, residual_applies);
}

}  // namespace trm
