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
//
// A view is decoded incrementally (StreamingView: begin, one push per input line, end), as the hardware receives it;
// decode() pushes a whole frame's lines through the same steps.
#include "fixed_core.hpp"
#include "line_ring.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace trm {

using fixed_detail::FixedDecoderCore;
using fixed_detail::LineRing;
using fixed_detail::Geometry;
using fixed_detail::Raw;

namespace {

constexpr const char* kWho = "FixedStreamingDecoder";

// The full-frame schedule, stepped once per input line: after input line y_in, on_reduced(k, y_in) for every reduced
// row of d_t whose vertical taps have all arrived and on_output(y, y_in, reduced_ready) for every output row whose U
// rows exist. Nothing is stepped before input line `first` of a view (concealment: lost lines above the first intact
// line take that line's content, so work that needs them waits for it; 0 normally).
// A band of a view (FixedDecoderConfig::threads) starts both counters at its first rows and stops its output at
// end_output; the steps are the whole view's, so a band's line buffers hold what they hold in a whole view.
struct FullSchedule {
  int next_reduced = 0;
  int next_output = 0;
  int end_output = std::numeric_limits<int>::max();

  template <typename OnReduced, typename OnOutput>
  void after_input(const Geometry& g, int y_in, OnReduced&& on_reduced, OnOutput&& on_output) {
    const int output_end = std::min(g.full.height, end_output);
    for (;;) {
      while (next_output < output_end && next_output <= y_in &&
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
};

// The reduced-frame schedule: after input line k, on_output(y, k) for every output row whose U rows i0, i1 <= k.
struct ReducedSchedule {
  int next_output = 0;
  int end_output = std::numeric_limits<int>::max();

  template <typename OnOutput>
  void after_input(const Geometry& g, int k, OnOutput&& on_output) {
    const int output_end = std::min(g.full.height, end_output);
    while (next_output < output_end && g.bilinear_rows[static_cast<std::size_t>(next_output)].i1 <= k) {
      on_output(next_output++, k);
    }
  }
};

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
  FullSchedule full;
  for (int y_in = 0; y_in < g.full.height; ++y_in) {
    full.after_input(
        g, y_in,
        [&](int k, int in) {
          p.gauss_lines = std::max(p.gauss_lines, in - g.gauss_rows[static_cast<std::size_t>(k)].first() + 1);
        },
        [&](int y, int in, int ready) {
          p.delay_lines = std::max(p.delay_lines, in - y + 1);
          p.full_latency = std::max(p.full_latency, in - y);
          p.low_lines = std::max(p.low_lines, ready - g.bilinear_rows[static_cast<std::size_t>(y)].i0);
        });
  }
  ReducedSchedule reduced;
  for (int k = 0; k < g.reduced.height; ++k) {
    reduced.after_input(g, k, [&](int y, int in) {
      const int i0 = g.bilinear_rows[static_cast<std::size_t>(y)].i0;
      p.reduced_lines = std::max(p.reduced_lines, in - i0 + 1);
      p.reduced_latency = std::max(p.reduced_latency, in - i0);
    });
  }
  return p;
}

}  // namespace

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

namespace fixed_detail {

// Bands per thread of a whole view (FixedStreamingDecoder::decode_in_bands): more than one, so that a thread held up
// by other work on its core leaves part of its share to the others, and few, as each band computes D's support above
// it again (docs/performance_history.md).
constexpr int kBandsPerThread = 2;

// The bands that start at the output rows `begins` (increasing from 0; the last ends at the view's end).
std::vector<RowBand> bands_from(const Geometry& g, const std::vector<int>& begins) {
  const std::size_t count = begins.size();
  std::vector<RowBand> bands(count);
  for (std::size_t b = 0; b < count; ++b) {
    RowBand& band = bands[b];
    band.begin = begins[b];
    band.end = b + 1 < count ? begins[b + 1] : g.full.height;
    band.reduced_begin = b == 0 ? 0 : g.bilinear_rows[static_cast<std::size_t>(band.begin)].i0;
  }
  for (std::size_t b = 0; b < count; ++b) {
    bands[b].reduced_end = b + 1 < count ? bands[b + 1].reduced_begin : g.reduced.height;
  }
  return bands;
}

std::vector<RowBand> row_bands(const Geometry& g, int threads) {
  const int count = std::max(1, std::min(threads, g.full.height / kMinBandRows));
  std::vector<int> begins(static_cast<std::size_t>(count));
  for (int b = 0; b < count; ++b) {
    begins[static_cast<std::size_t>(b)] = static_cast<int>(static_cast<std::int64_t>(g.full.height) * b / count);
  }
  return bands_from(g, begins);
}

std::vector<RowBand> balanced_bands(const Geometry& g, int count, const BandTimes& last) {
  const int height = g.full.height;
  count = std::max(1, std::min(count, height / kMinBandRows));
  const std::size_t n = last.begins.size();
  bool usable = count > 1 && last.height == height && n >= 1 && last.seconds.size() == n && last.begins[0] == 0;
  double total = 0.0;
  for (std::size_t b = 0; usable && b < n; ++b) {
    const int end = b + 1 < n ? last.begins[b + 1] : height;
    usable = end > last.begins[b] && std::isfinite(last.seconds[b]) && last.seconds[b] > 0.0;
    total += usable ? last.seconds[b] : 0.0;
  }
  if (!usable) return row_bands(g, count);
  std::vector<int> begins{0};
  std::size_t b = 0;       // the last view's band holding the row reached
  double before_b = 0.0;   // the cost of the last view's bands before b
  for (int k = 1; k < count; ++k) {
    const double wanted = total * k / count;
    while (b + 1 < n && before_b + last.seconds[b] <= wanted) before_b += last.seconds[b++];
    const int first = last.begins[b];
    const int end = b + 1 < n ? last.begins[b + 1] : height;
    const int row = first + static_cast<int>((wanted - before_b) / last.seconds[b] * (end - first));
    if (row - begins.back() < kMinBandRows / 2 || height - row < kMinBandRows / 2) return row_bands(g, count);
    begins.push_back(row);
  }
  return bands_from(g, begins);
}

// One view in flight through the streaming schedule, line by line.
//
// Concealment in raster order (the reference's rules, line by line as the lines arrive):
//   * a lost line below an intact one repeats the line just above it, which the input ring (E_t delay or U of i)
//     still holds already concealed: by induction that is the nearest intact line above. No storage is added.
//   * lost lines above the first intact line of the view (nothing intact above them) are copies of that line (the
//     nearest intact line below): no data is kept for them, and every read of such a line reads the first intact
//     line instead, like a replicate border moved down to it. Work that needs them waits for that line, so such a
//     view's output starts up to first_intact lines later than normal.
//   * a lost line of a reduced frame with a stored d_{t-1} takes that frame store's row (an extra row read). Whether
//     the view is partial or lost whole is known at its first intact line, so lost lines above it are taken then.
// Lost lines of a full frame then show L_t (full_line), as in the frame-at-a-time schedule. A view without any
// intact line is a lost view (decode_lost): nothing of it is computed before its end.
class StreamingView {
 public:
  StreamingView(FixedDecoderCore& core, const FrameMeta& meta)
      : core_(core),
        meta_(meta),
        // Looked up before begin(), which resets an eye whose view size changed (as classify() does for decode).
        substitute_(core.concealment_substitute(meta)),
        intact_(static_cast<std::size_t>(meta.height), 0) {}

  const FrameMeta& meta() const { return meta_; }
  int lines_pushed() const { return pushed_; }
  int input_samples() const { return 3 * meta_.width; }
  int rows_ready() const {
    if (!started_) return 0;
    return full_ ? full_schedule_.next_output : reduced_schedule_.next_output;
  }
  const std::uint16_t* drive_row(int y) const { return out_.frame.drive_codes.ptr<std::uint16_t>(y); }

  // codes: input_samples() link codes, already checked; null for a lost line.
  void push(const std::uint16_t* codes) {
    const int line = pushed_++;
    intact_[static_cast<std::size_t>(line)] = codes != nullptr ? 1 : 0;
    lost_lines_ += codes != nullptr ? 0 : 1;
    if (!started_) {
      if (codes == nullptr) return;  // nothing intact yet: lost whole, or held back until the first intact line
      start(line);
      // With a d_{t-1} to take them from, the lost lines above are concealed now, in order; without one `first_` is
      // this line and they are read as it.
      for (int k = first_; k < line; ++k) input(k, nullptr);
    }
    input(line, codes);
  }

  // A whole view decoded in bands: `band_view` builds a band's view over the same frame stores and output (with its
  // own line buffers and an empty line scratch), run_band computes a band from the whole view's codes, add_tally_to
  // and absorb join the bands' tallies into this view, which runs none.
  void open_whole() {
    start(0);
    std::fill(intact_.begin(), intact_.end(), std::uint8_t{1});
  }
  std::unique_ptr<StreamingView> band_view(const RowBand& band) const {
    auto view = std::unique_ptr<StreamingView>(new StreamingView(*this));
    view->out_.tally = FrameTally();
    view->scratch_ = LineScratch();  // line working memory, sized at first use
    view->limit_to(band);
    return view;
  }
  void limit_to(const RowBand& band) {
    const Geometry& g = *g_;
    const int first_reduced = g.bilinear_rows[static_cast<std::size_t>(band.begin)].i0;
    store_begin_ = band.reduced_begin;
    store_end_ = band.reduced_end;
    if (full_) {
      full_schedule_.next_output = band.begin;
      full_schedule_.next_reduced = first_reduced;
      full_schedule_.end_output = band.end;
      band_first_input_ = std::min(band.begin, g.gauss_rows[static_cast<std::size_t>(first_reduced)].first());
    } else {
      reduced_schedule_.next_output = band.begin;
      reduced_schedule_.end_output = band.end;
      band_first_input_ = first_reduced;
    }
    band_end_ = band.end;
  }
  void run_band(const cv::Mat& codes) {
    for (int line = band_first_input_; line < codes.rows && !band_done(); ++line) {
      input(line, codes.ptr<std::uint16_t>(line));
    }
  }
  void add_tally_to(FrameTally& total) const { total += out_.tally; }
  void absorb(const FrameTally& bands) { out_.tally += bands; }
  void mark_all_pushed() { pushed_ = meta_.height; }
  // The view is a whole frame given to decode (not lines pushed): its codes have all passed their range check before
  // the first line (FixedDecoderCore::start_output may then take the held output's plane), and its rows outlive the
  // view (the input rings hold them where they are).
  void mark_whole_frame() { whole_frame_ = true; }
  // The eye's record of its last view of this kind decoded in bands.
  BandTimes& band_times() { return eye_->band_times[full_ ? 1 : 0]; }

  DecodedFrame finish() {
    if (!started_) return core_.decode_lost(meta_, kWho);
    out_.concealed_lines = lost_lines_;
    EyeState& eye = *eye_;
    if (full_) {
      eye.have_residual = true;
      eye.residual_index = meta_.index;
      eye.residual = residual_store_;
      eye.previous_low = low_store_;
      return core_.finish(std::move(out_), eye, true, false);
    }
    eye.have_residual = false;
    eye.residual.release();
    eye.previous_low.release();
    return core_.finish(std::move(out_), eye, false, residual_applies_);
  }

 private:
  StreamingView(const StreamingView&) = default;

  bool band_done() const {
    if (full_) return full_schedule_.next_output >= band_end_ && full_schedule_.next_reduced >= store_end_;
    return reduced_schedule_.next_output >= band_end_;
  }
  bool lost(int line) const { return intact_[static_cast<std::size_t>(line)] == 0; }
  // Lines above the first intact line read as the first intact line.
  int source_line(int line) const { return std::max(line, first_); }

  void start(int first_intact) {
    started_ = true;
    first_ = substitute_.empty() ? first_intact : 0;
    eye_ = &core_.begin(meta_);
    EyeState& eye = *eye_;
    g_ = &core_.kernels().geometry(eye.full_size);
    const Geometry& g = *g_;
    const StreamPlan plan = plan_for(g);
    full_ = meta_.parity == Parity::Full;
    out_ = core_.start_output(meta_, eye, whole_frame_);
    out_.full = full_;
    core_.begin_lcd(out_, eye);
    const int full_samples = 3 * g.full.width;
    const int reduced_samples = 3 * g.reduced.width;
    if (full_) {
      delay_.emplace("E_t delay", plan.delay_lines, full_samples);
      // D's line buffer in 32-bit words where its values fit them: half the bytes the vertical half reads.
      if (core_.kernels().narrow_gaussian_lines()) {
        gauss_.reset();
        gauss32_.emplace("vertical Gaussian", plan.gauss_lines, reduced_samples);
      } else {
        gauss32_.reset();
        gauss_.emplace("vertical Gaussian", plan.gauss_lines, reduced_samples);
      }
      low_lines_.emplace("U of d_t", plan.low_lines, reduced_samples);
      // DESIGN §7 chroma skip: a grey flag beside each line of the three line buffers.
      delay_grey_.emplace("E_t delay grey flags", plan.delay_lines, 1);
      gauss_grey_.emplace("vertical Gaussian grey flags", plan.gauss_lines, 1);
      low_grey_.emplace("U of d_t grey flags", plan.low_lines, 1);
      residual_store_ = reusable_plane(eye.spare_planes, g.full, CV_32SC3);  // frame store rho
      low_store_ = reusable_plane(eye.spare_planes, g.reduced, CV_16UC3);    // frame store d_t
      core_.start_full_lines(eye, g);
      return;
    }
    // meta.index >= 0 (checked by check_view_header), so index - 1 cannot overflow.
    residual_applies_ = eye.have_residual && eye.residual_index == meta_.index - 1;
    in_lines_.emplace("U of i", plan.reduced_lines, reduced_samples);
    in_grey_.emplace("U of i grey flags", plan.reduced_lines, 1);
    // DESIGN §7 static skip: the line comparator's result for each line held in the U buffer (2 bits per line).
    gated_ = residual_applies_ && core_.skipping();
    line_flags_.emplace("U of i comparator flags", plan.reduced_lines, 1);
  }

  // Input line `line` (codes null: lost) and the schedule's steps after it.
  void input(int line, const std::uint16_t* codes) {
    if (full_) {
      full_input(line, codes);
      full_schedule_.after_input(
          *g_, line, [this](int k, int) { reduced_row(k); }, [this](int y, int, int) { full_output(y); });
    } else {
      reduced_input(line, codes);
      reduced_schedule_.after_input(*g_, line, [this](int y, int) { reduced_output(y); });
    }
  }

  void full_input(int y_in, const std::uint16_t* codes) {
    const Geometry& g = *g_;
    const int full_samples = 3 * g.full.width;
    if (codes == nullptr) {
      repeat_line(*delay_, y_in, full_samples);
    } else if (whole_frame_) {
      delay_->refer(y_in, codes);
    } else {
      std::copy(codes, codes + full_samples, delay_->write(y_in));
    }
    const std::uint16_t* in = delay_->read(y_in);
    const bool grey = core_.skipping() && FixedKernels::grey_line(in, g.full.width);
    *delay_grey_->write(y_in) = grey ? 1 : 0;
    *gauss_grey_->write(y_in) = grey ? 1 : 0;
    if (gauss32_) {
      core_.kernels().gaussian_horizontal_line(in, g, gauss32_->write(y_in), grey);
    } else {
      core_.kernels().gaussian_horizontal_line(in, g, gauss_->write(y_in), grey);
    }
  }

  void reduced_row(int k) {
    const Geometry& g = *g_;
    const PolyphaseTaps& taps = g.gauss_rows[static_cast<std::size_t>(k)];
    std::uint16_t* d = low_lines_->write(k);
    const FixedKernels& kernels = core_.kernels();
    const int reduced_samples = 3 * g.reduced.width;
    const bool store = k >= store_begin_ && k < store_end_;
    const bool grey = core_.reduced_row_grey(out_, *eye_, g, k, store, [this](int line) {
      return *gauss_grey_->read(source_line(line)) != 0;
    });
    *low_grey_->write(k) = grey ? 1 : 0;
    const auto vertical = [&](const auto& ring, auto& tap_rows) {
      tap_rows.clear();
      for (int index : taps.index) tap_rows.push_back(ring.read(source_line(index)));
      kernels.gaussian_vertical_row(tap_rows.data(), taps, reduced_samples, d, grey);
    };
    if (gauss32_) {
      vertical(*gauss32_, tap_rows32_);
    } else {
      vertical(*gauss_, tap_rows_);
    }
    if (store) std::copy(d, d + reduced_samples, low_store_.ptr<std::uint16_t>(k));
  }

  void full_output(int y) {
    const Geometry& g = *g_;
    const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
    const std::uint16_t* codes_row = delay_->read(source_line(y));
    const std::uint16_t* low0 = low_lines_->read(row.i0);
    const std::uint16_t* low1 = low_lines_->read(row.i1);
    std::int32_t* residual_row = residual_store_.ptr<std::int32_t>(y);
    const bool lost_line = lost(y);
    const bool grey = core_.full_line_grey(out_, *delay_grey_->read(source_line(y)) != 0, *low_grey_->read(row.i0) != 0,
                                           *low_grey_->read(row.i1) != 0);
    core_.full_line(out_, *eye_, g, y, codes_row, low0, low1, residual_row, lost_line, grey, scratch_);
    core_.end_full_line(out_, *eye_, y, residual_row, scratch_);
  }

  void reduced_input(int k, const std::uint16_t* codes) {
    const int reduced_samples = 3 * g_->reduced.width;
    if (codes != nullptr && whole_frame_) {
      in_lines_->refer(k, codes);
    } else if (codes != nullptr) {
      std::copy(codes, codes + reduced_samples, in_lines_->write(k));
    } else if (!substitute_.empty()) {
      const std::uint16_t* stored = substitute_.ptr<std::uint16_t>(k);  // d_{t-1} frame store row k
      std::copy(stored, stored + reduced_samples, in_lines_->write(k));
    } else {
      repeat_line(*in_lines_, k, reduced_samples);
    }
    *in_grey_->write(k) = core_.skipping() && FixedKernels::grey_line(in_lines_->read(k), g_->reduced.width) ? 1 : 0;
    if (gated_) {  // compared as the line enters the U buffer, against the d_{t-1} frame store row k
      *line_flags_->write(k) =
          FixedKernels::compare_line(eye_->previous_low.ptr<std::uint16_t>(k), in_lines_->read(k), reduced_samples);
    }
  }

  void reduced_output(int y) {
    const Geometry& g = *g_;
    EyeState& eye = *eye_;
    const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
    const std::uint16_t* in0 = in_lines_->read(source_line(row.i0));
    const std::uint16_t* in1 = in_lines_->read(source_line(row.i1));
    ReducedLineGate gate;
    if (gated_) {
      // Lines above `first_` (never held) do not skip.
      gate = core_.reduced_line_gate(out_, eye, g, y, [this](int k) -> std::uint8_t {
        return k < first_ ? 0 : *line_flags_->read(k);
      });
    }
    const bool read_previous = residual_applies_ && gate.reads_previous();
    const std::uint16_t* prev0 = read_previous ? eye.previous_low.ptr<std::uint16_t>(row.i0) : nullptr;
    const std::uint16_t* prev1 = read_previous ? eye.previous_low.ptr<std::uint16_t>(row.i1) : nullptr;
    const std::int32_t* residual_row =
        residual_applies_ && !gate.residual_zero ? eye.residual.ptr<std::int32_t>(y) : nullptr;
    const bool grey = core_.reduced_line_grey(out_, eye, g, y, *in_grey_->read(source_line(row.i0)) != 0,
                                              *in_grey_->read(source_line(row.i1)) != 0, residual_applies_, gate);
    core_.reduced_line(out_, eye, g, y, in0, in1, prev0, prev1, residual_row, gated_ ? &gate : nullptr, grey,
                       scratch_);
  }

  FixedDecoderCore& core_;
  FrameMeta meta_;
  cv::Mat substitute_;  // reduced frames: the eye's d_{t-1} frame store (codes) for lost lines; empty: none
  std::vector<std::uint8_t> intact_;  // per input line pushed; 0 = lost
  int pushed_ = 0;
  int lost_lines_ = 0;
  bool started_ = false;  // the first intact line has arrived
  bool whole_frame_ = false;  // mark_whole_frame
  int first_ = 0;         // lines above it are read as it (see source_line)
  bool full_ = false;
  EyeState* eye_ = nullptr;
  const Geometry* g_ = nullptr;
  FrameOutput out_;
  FullSchedule full_schedule_;
  ReducedSchedule reduced_schedule_;
  // Full frames: line buffers and the frame stores this frame writes.
  std::optional<LineRing<std::uint16_t>> delay_;
  std::optional<LineRing<Raw>> gauss_;
  std::optional<LineRing<std::uint32_t>> gauss32_;  // in its place where narrow_gaussian_lines
  std::optional<LineRing<std::uint16_t>> low_lines_;
  cv::Mat residual_store_;
  cv::Mat low_store_;
  std::vector<const Raw*> tap_rows_;
  std::vector<const std::uint32_t*> tap_rows32_;
  fixed_detail::LineScratch scratch_;
  // Reduced frames.
  bool residual_applies_ = false;
  bool gated_ = false;
  std::optional<LineRing<std::uint16_t>> in_lines_;
  std::optional<LineRing<std::uint8_t>> line_flags_;
  // Grey flags (chroma skip) beside the line buffers.
  std::optional<LineRing<std::uint8_t>> delay_grey_;
  std::optional<LineRing<std::uint8_t>> gauss_grey_;
  std::optional<LineRing<std::uint8_t>> low_grey_;
  std::optional<LineRing<std::uint8_t>> in_grey_;
  // A band (run_band): d_t rows it stores, its first input line, its output end.
  int store_begin_ = 0;
  int store_end_ = std::numeric_limits<int>::max();
  int band_first_input_ = 0;
  int band_end_ = std::numeric_limits<int>::max();
};

}  // namespace fixed_detail

FixedStreamingDecoder::FixedStreamingDecoder(FixedDecoderConfig config)
    : core_(std::make_unique<FixedDecoderCore>(std::move(config))) {}
FixedStreamingDecoder::~FixedStreamingDecoder() = default;
FixedStreamingDecoder::FixedStreamingDecoder(FixedStreamingDecoder&&) noexcept = default;
FixedStreamingDecoder& FixedStreamingDecoder::operator=(FixedStreamingDecoder&&) noexcept = default;
const FixedDecoderConfig& FixedStreamingDecoder::config() const { return core_->config(); }
const FixedStageCounts& FixedStreamingDecoder::last_counts() const { return core_->last_counts(); }

int FixedStreamingDecoder::threads_for(cv::Size full) const {
  return static_cast<int>(fixed_detail::row_bands(core_->kernels().geometry(full), core_->config().threads).size());
}

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
    // The chroma skip: a grey flag beside every line of the four line buffers, per row of the d_t store and per
    // line of the residual store.
    add_frame_store("line: grey flags beside the E_t delay, vertical Gaussian, U of d_t and U of i lines",
                    p.delay_lines + p.gauss_lines + p.low_lines + p.reduced_lines, 1, 1);
    add_frame_store("frame: grey flags of the d_t rows and the residual lines (chroma skip)",
                    g.reduced.height + g.full.height, 1, 1);
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
    FixedArithmeticReport& grey = r.arithmetic.emplace_back();
    grey.stage = "grey detector R = G = B (chroma skip), input and residual lines";
    grey.frame = "both";
    grey.evaluated_per = "pixel";
    grey.evaluations = static_cast<std::int64_t>(g.full.width) * g.full.height;
    grey.comparators = 2;
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

DecodedFrame FixedStreamingDecoder::decode(const LinkFrame& frame) { return decode_checked(frame, {}); }

DecodedFrame FixedStreamingDecoder::decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  return decode_checked(frame, line_intact);
}

DecodedFrame FixedStreamingDecoder::decode_lost(const FrameMeta& meta) {
  if (view_) {
    throw std::logic_error(std::string(kWho) + ": decode_lost while " + detail::frame_name(view_->meta()) +
                           " is still open");
  }
  return core_->decode_lost(meta, kWho);
}

DecodedFrame FixedStreamingDecoder::decode_checked(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  detail::Concealment lost;
  // The mask first, as the other decoders check it; a view with no intact line is a lost view and its codes are not
  // looked at.
  if (detail::classify_arrival(frame, line_intact, lost, kWho) == detail::Arrival::Lost) return decode_lost(frame.meta);
  const bool whole = std::all_of(line_intact.begin(), line_intact.end(), [](std::uint8_t v) { return v != 0; });
  detail::check_link_frame(frame, core_->config().decoder.link, kWho, whole ? core_->config().threads : 1);
  begin_view(frame.meta);
  view_->mark_whole_frame();
  if (whole && core_->config().threads > 1) return decode_in_bands(frame);
  for (int y = 0; y < frame.codes.rows; ++y) {
    take_line(frame.codes.ptr<std::uint16_t>(y), line_intact.empty() || line_intact[static_cast<std::size_t>(y)] != 0);
  }
  return end_view();
}

DecodedFrame FixedStreamingDecoder::decode_in_bands(const LinkFrame& frame) {
  try {
    view_->open_whole();
    const fixed_detail::Geometry& g =
        core_->kernels().geometry(cv::Size(frame.meta.full_width, frame.meta.full_height));
    const std::size_t threads = fixed_detail::row_bands(g, core_->config().threads).size();
    // More bands than threads, each taken by the next thread free: a thread held up by other work on its core (a
    // feed's reading and sending) leaves the rest of the view to the others instead of keeping them waiting.
    fixed_detail::BandTimes& times = view_->band_times();
    const std::vector<fixed_detail::RowBand> bands =
        fixed_detail::balanced_bands(g, core_->config().threads * fixed_detail::kBandsPerThread, times);
    std::vector<double> band_seconds(bands.size(), 0.0);
    // Each band's view is built when a thread takes the band, as a copy of this view, which runs none and so keeps
    // the state every band starts from, and let go when its tally is in: as many band views at a time as threads.
    std::vector<std::exception_ptr> failed(bands.size());
    std::atomic<std::size_t> next_band{0};
    std::mutex tally_mutex;
    fixed_detail::FrameTally bands_tally;
    const auto run_bands = [&] {
      for (std::size_t b; (b = next_band.fetch_add(1, std::memory_order_relaxed)) < bands.size();) {
        try {
          const auto start = std::chrono::steady_clock::now();
          const std::unique_ptr<fixed_detail::StreamingView> band = view_->band_view(bands[b]);
          band->run_band(frame.codes);
          band_seconds[b] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          const std::lock_guard lock(tally_mutex);
          band->add_tally_to(bands_tally);
        } catch (...) {
          failed[b] = std::current_exception();
        }
      }
    };
    {
      std::vector<std::jthread> workers;
      for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(run_bands);
      run_bands();
    }  // joined
    for (const std::exception_ptr& e : failed) {
      if (e) std::rethrow_exception(e);
    }
    times.height = g.full.height;
    times.begins.clear();
    for (const fixed_detail::RowBand& band : bands) times.begins.push_back(band.begin);
    times.seconds = std::move(band_seconds);
    view_->absorb(bands_tally);
    view_->mark_all_pushed();
  } catch (...) {
    view_.reset();
    throw;
  }
  return end_view();
}

void FixedStreamingDecoder::begin_view(const FrameMeta& meta) {
  if (view_) {
    throw std::logic_error(std::string(kWho) + ": " + detail::frame_name(meta) + " begun while " +
                           detail::frame_name(view_->meta()) + " is still open");
  }
  detail::check_view_header(meta, core_->config().decoder.link, kWho);
  view_ = std::make_unique<fixed_detail::StreamingView>(*core_, meta);
}

int FixedStreamingDecoder::push_line(std::span<const std::uint16_t> codes, bool intact) {
  if (!view_) throw std::logic_error(std::string(kWho) + ": a line pushed without an open view");
  const FrameMeta& meta = view_->meta();
  const std::string what = std::string(kWho) + ": " + detail::frame_name(meta) + ": ";
  if (view_->lines_pushed() >= meta.height) {
    throw std::logic_error(what + "a line pushed after all " + std::to_string(meta.height) + " lines of the view");
  }
  if (intact) {
    if (codes.size() != static_cast<std::size_t>(view_->input_samples())) {
      throw std::invalid_argument(what + "line " + std::to_string(view_->lines_pushed()) + " has " +
                                  std::to_string(codes.size()) + " samples, the view's lines have " +
                                  std::to_string(view_->input_samples()) + " (3 x " + std::to_string(meta.width) +
                                  ")");
    }
    detail::check_line_codes(meta, view_->lines_pushed(), codes, meta.bits, kWho);
  }
  take_line(intact ? codes.data() : nullptr, intact);
  return view_->rows_ready();
}

void FixedStreamingDecoder::take_line(const std::uint16_t* codes, bool intact) {
  try {
    view_->push(intact ? codes : nullptr);
  } catch (...) {
    view_.reset();  // half a line computed: the view cannot go on
    throw;
  }
}

int FixedStreamingDecoder::rows_ready() const { return view_ ? view_->rows_ready() : 0; }

std::span<const std::uint16_t> FixedStreamingDecoder::drive_row(int y) const {
  if (!view_ || y < 0 || y >= view_->rows_ready()) {
    throw std::out_of_range(std::string(kWho) + ": output row " + std::to_string(y) + " is not ready");
  }
  return {view_->drive_row(y), static_cast<std::size_t>(3 * view_->meta().full_width)};
}

bool FixedStreamingDecoder::view_open() const { return view_ != nullptr; }
int FixedStreamingDecoder::lines_pushed() const { return view_ ? view_->lines_pushed() : 0; }

DecodedFrame FixedStreamingDecoder::end_view() {
  if (!view_) throw std::logic_error(std::string(kWho) + ": end of view without an open view");
  if (view_->lines_pushed() != view_->meta().height) {
    throw std::logic_error(std::string(kWho) + ": " + detail::frame_name(view_->meta()) + ": end of view after " +
                           std::to_string(view_->lines_pushed()) + " of its " + std::to_string(view_->meta().height) +
                           " lines");
  }
  std::unique_ptr<fixed_detail::StreamingView> view = std::move(view_);
  return view->finish();
}

}  // namespace trm
