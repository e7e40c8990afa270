// The state and plumbing both fixed-point schedules share (fixed_core.hpp): eye states, output, LCD frame stores,
// the per-pixel full and reduced frame steps, skip gates, stage taps and statistics.
#include "fixed_core.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace trm::fixed_detail {

FixedDecoderCore::FixedDecoderCore(FixedDecoderConfig config) : kernels_(config) {}

EyeState& FixedDecoderCore::begin(const LinkFrame& frame, const char* who) {
  detail::check_link_frame(frame, kernels_.config().decoder.link, who);
  return begin(frame.meta);
}

EyeState& FixedDecoderCore::begin(const FrameMeta& meta) {
  const cv::Size full(meta.full_width, meta.full_height);
  EyeState& eye = eyes_[meta.eye];
  if (eye.full_size != full) {
    eye = EyeState();
    eye.full_size = full;
  }
  return eye;
}

namespace {

// Whether any of n values is not 0, compiled for AVX2 too and chosen at run time (GCC's function multi-versioning):
// the residual flags of a full line, read over each run it stores.
[[gnu::target_clones("avx2", "default")]] bool any_nonzero(const std::int32_t* values, std::size_t n) {
  std::int32_t any_bits = 0;
  for (std::size_t i = 0; i < n; ++i) any_bits |= values[i];
  return any_bits != 0;
}

}  // namespace

FrameOutput FixedDecoderCore::start_output(const FrameMeta& meta, EyeState& eye, bool codes_checked) const {
  FrameOutput out;
  const cv::Size full(meta.full_width, meta.full_height);
  out.frame.meta = meta;
  out.frame.meta.width = full.width;
  out.frame.meta.height = full.height;
  const bool planes = config().decoder.report_planes;
  // A spare plane is free where the spare list alone holds it, or, for a view whose codes were all checked, the held
  // output (read only for a lost view) besides: that view then takes the held output's planes, and the held output
  // is let go for them (finish holds this view's instead), so that an eye keeps one output where no caller keeps any.
  const DecodedFrame& held = eye.last_output;
  const auto free_plane = [&](const cv::Mat& plane, const cv::Mat& held_plane) {
    return plane.u != nullptr && plane_owners(plane) == (codes_checked && plane.u == held_plane.u ? 2 : 1);
  };
  // A spare with report planes where they are wanted (and none where not: the held output keeps the codes only).
  const auto fits = [&](const cv::Mat& plane, const cv::Mat& held_plane) {
    return planes ? free_plane(plane, held_plane) : plane.empty();
  };
  for (const DecodedFrame& spare : eye.spare_outputs) {
    if (free_plane(spare.drive_codes, held.drive_codes) && fits(spare.wanted_linear, held.wanted_linear) &&
        fits(spare.drive, held.drive) && fits(spare.emitted_linear, held.emitted_linear)) {
      if (spare.drive_codes.u == held.drive_codes.u) eye.last_output = DecodedFrame();
      out.frame.wanted_linear = spare.wanted_linear;
      out.frame.drive = spare.drive;
      out.frame.drive_codes = spare.drive_codes;
      out.frame.emitted_linear = spare.emitted_linear;
      return out;
    }
  }
  out.frame.drive_codes = frame_plane(full, CV_16UC3);
  if (planes) {
    out.frame.wanted_linear = frame_plane(full, CV_64FC3);
    out.frame.drive = frame_plane(full, CV_64FC3);
    out.frame.emitted_linear = frame_plane(full, CV_64FC3);
  }
  // Two in flight (the one returned and the held output) and one being filled cover a caller that keeps one view.
  constexpr std::size_t kSpareOutputs = 3;
  DecodedFrame spare;
  spare.wanted_linear = out.frame.wanted_linear;
  spare.drive = out.frame.drive;
  spare.drive_codes = out.frame.drive_codes;
  spare.emitted_linear = out.frame.emitted_linear;
  if (eye.spare_outputs.size() < kSpareOutputs) eye.spare_outputs.push_back(std::move(spare));
  return out;
}

void FixedDecoderCore::begin_lcd(FrameOutput& out, EyeState& eye) const {
  if (!kernels_.lcd()) return;
  out.lcd_held = eye.lcd_previous_drive.empty();
  if (out.lcd_held) {
    // Not read on the held frame (lcd_drive takes x_{t-1} = x_t and the held code); zeroed to stay defined.
    eye.lcd_previous_drive = frame_plane(eye.full_size, kernels_.max_output_code() <= 255 ? CV_8UC3 : CV_16UC3);
    eye.lcd_previous_linear = frame_plane(eye.full_size, CV_32SC3);
    eye.lcd_previous_drive.setTo(0);
    eye.lcd_previous_linear.setTo(0);
  }
}

Raw FixedDecoderCore::emit(FrameOutput& out, EyeState& eye, int y, int x, int ch, Raw wanted) const {
  const int k = 3 * x + ch;
  const bool planes = config().decoder.report_planes;
  if (planes) out.frame.wanted_linear.ptr<double>(y)[k] = kernels_.linear_to_double(wanted);
  if (!kernels_.lcd()) {
    const std::uint16_t code = kernels_.drive_code(wanted, ch);
    out.frame.drive_codes.ptr<std::uint16_t>(y)[k] = code;
    if (planes) {
      out.frame.drive.ptr<double>(y)[k] = kernels_.drive_to_double(kernels_.drive_value(wanted, ch));
      out.frame.emitted_linear.ptr<double>(y)[k] = kernels_.emitted(code, 0, ch);
    }
    return 0;
  }
  // LCD frame stores: v_{t-1} and x_{t-1} at this sample are read, then replaced by this frame's.
  const bool narrow_store = eye.lcd_previous_drive.depth() == CV_8U;
  std::uint8_t* previous_code8 = narrow_store ? eye.lcd_previous_drive.ptr<std::uint8_t>(y) + k : nullptr;
  std::uint16_t* previous_code16 = narrow_store ? nullptr : eye.lcd_previous_drive.ptr<std::uint16_t>(y) + k;
  std::int32_t& previous_linear = eye.lcd_previous_linear.ptr<std::int32_t>(y)[k];
  const std::uint16_t previous_code = narrow_store ? *previous_code8 : *previous_code16;
  const LcdSample s = kernels_.lcd_drive(wanted, previous_linear, previous_code, out.lcd_held, planes);
  out.frame.drive_codes.ptr<std::uint16_t>(y)[k] = s.code;
  out.tally.counts.lcd_unreachable += s.unreachable ? 1 : 0;
  const bool contributed = config().decoder.lcd_history == LcdHistory::Contributed;
  if (planes) {
    out.frame.drive.ptr<double>(y)[k] = kernels_.drive_to_double(s.drive);
    out.frame.emitted_linear.ptr<double>(y)[k] = kernels_.emitted(s.code, s.previous_code, ch);
  }
  if (narrow_store) {
    *previous_code8 = static_cast<std::uint8_t>(s.code);
  } else {
    *previous_code16 = s.code;
  }
  previous_linear = static_cast<std::int32_t>(contributed ? s.contributed : wanted);
  return out.full ? s.shortfall : 0;
}

const std::uint32_t* ColumnBlendCache::row(const std::uint16_t* codes, int index, const ColumnBlendPlan& plan) {
  for (const Entry& e : entries_) {
    if (e.codes == codes && e.index == index) return e.blended.data();
  }
  Entry& e = entries_[next_];
  next_ ^= 1;
  e.codes = codes;
  e.index = index;
  e.blended.resize(plan.upper.size());
  lines::blend_columns(codes, plan, plan.upper.size(), e.blended.data());
  return e.blended.data();
}

namespace {

// U and lin() of output line y through the line kernels: the column blends of its two source rows (cached), then
// the row blend and the EOTF, into a line of either width.
template <typename Line>
void blend_line(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y, const EotfPlan& eotf,
                ColumnBlendCache& cache, Line* out, std::size_t begin = 0,
                std::size_t end = std::numeric_limits<std::size_t>::max()) {
  const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
  const std::uint32_t* top = cache.row(row0, row.i0, g.column_blend);
  const std::uint32_t* bottom = cache.row(row1, row.i1, g.column_blend);
  end = std::min(end, g.column_blend.upper.size());
  lines::blend_rows_eotf(top + begin, bottom + begin, end - begin, static_cast<std::uint32_t>(row.upper),
                         g.column_blend.weight_bits, eotf, out + begin);
}

// The drive codes of output line y straight from U's nodes (lines::blend_rows_drive); false where the plans have no
// composed table (an LCD; a node outside [0, 1]) or its exact path does not apply to the row.
bool blend_line_codes(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y,
                      const FixedLinePlans& plans, ColumnBlendCache& cache, std::uint16_t* codes) {
  const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
  const std::uint32_t upper = static_cast<std::uint32_t>(row.upper);
  if (plans.drive_of_node.empty() || plans.eotf->exact_row_bits(upper, g.column_blend.weight_bits) < 0) return false;
  const std::uint32_t* top = cache.row(row0, row.i0, g.column_blend);
  const std::uint32_t* bottom = cache.row(row1, row.i1, g.column_blend);
  return lines::blend_rows_drive(top, bottom, g.column_blend.upper.size(), upper, g.column_blend.weight_bits,
                                 *plans.eotf, plans.drive_of_node, codes);
}

}  // namespace

void FixedDecoderCore::upsample(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y,
                                Raw* out, bool grey, ColumnBlendCache& cache) const {
  const BilinearWeights& row = g.bilinear_rows[static_cast<std::size_t>(y)];
  const std::optional<EotfPlan>& eotf = kernels_.line_plans().eotf;
  if (!eotf) {
    kernels_.upsample_line(row0, row1, g, row.upper, out, grey);
    return;
  }
  // Every channel, grey or not: the grey line's copies are the same bits, and the vector lanes cost no more.
  blend_line(row0, row1, g, y, *eotf, cache, out);
}

void FixedDecoderCore::upsample(const std::uint16_t* row0, const std::uint16_t* row1, const Geometry& g, int y,
                                std::int32_t* out, ColumnBlendCache& cache) const {
  blend_line(row0, row1, g, y, *kernels_.line_plans().eotf, cache, out);
}

void FixedDecoderCore::full_line(FrameOutput& out, EyeState& eye, const Geometry& g, int y,
                                 const std::uint16_t* codes_row, const std::uint16_t* low0, const std::uint16_t* low1,
                                 std::int32_t* residual_row, bool lost, bool grey, LineScratch& scratch) const {
  const int samples = 3 * g.full.width;
  const auto n = static_cast<std::size_t>(samples);
  const FixedLinePlans& plans = kernels_.line_plans();
  if (!lost && narrow_lines(out)) {  // the line kernels on 32-bit lines, the same steps as below
    scratch.first32.resize(n);
    scratch.shown32.resize(n);
    scratch.rho32.resize(n);
    upsample(low0, low1, g, y, scratch.first32.data(), scratch.first_rows);  // L_t
    const std::uint64_t clipped = lines::compensate(codes_row, scratch.first32.data(), n, plans,
                                                    scratch.shown32.data(), scratch.rho32.data());
    out.tally.clipped += clipped;
    out.tally.counts.beta_clipped += clipped;
    ResidualTally stored;
    if (plans.lcd) {
      // rho plus the shortfall in 64 bits: with the contributed history x_{t-1} may leave [0, 1], and the shortfall
      // with it (the residual store saturates what leaves its format).
      scratch.shortfall.resize(n);
      emit_line(out, eye, y, scratch.shown32.data(), scratch.shortfall.data());
      Raw* rho = scratch.shortfall.data();
      for (std::size_t s = 0; s < n; ++s) rho[s] += scratch.rho32[s];
      scratch.residual_nonzero = lines::store_residuals(rho, n, kernels_, residual_row, stored);
    } else if (clipped == 0) {  // rho = beta - clamp(beta) is 0 on the whole line, and so is what the store holds
      emit_line(out, eye, y, scratch.shown32.data(), nullptr);
      std::fill_n(residual_row, n, 0);
      scratch.residual_nonzero = false;
    } else {
      emit_line(out, eye, y, scratch.shown32.data(), nullptr);
      scratch.residual_nonzero = lines::store_residuals(scratch.rho32.data(), n, kernels_, residual_row, stored);
    }
    out.tally.add(stored);
    return;
  }
  scratch.residual_nonzero.reset();
  scratch.first.resize(n);
  upsample(low0, low1, g, y, scratch.first.data(), grey, scratch.first_rows);  // L_t
  // An LCD line: its drive over the line too (the eye's first frame included), whose shortfall joins rho (Sec. 4.4).
  const bool lcd_line = !line_kernels(out) && line_values(out) && plans.lcd;
  if (lost || !(line_kernels(out) || lcd_line)) {
    for (int x = 0; x < g.full.width; ++x) {
      full_pixel(out, eye, y, x, codes_row, scratch.first.data() + 3 * x, residual_row, lost, grey);
    }
    return;
  }
  // The line kernels: Eq. 2 and the split over the line, the drive codes of the shown values, then the residual
  // store, whose rounding and saturation act only where rho is not zero.
  scratch.shown.resize(n);
  scratch.rho.resize(n);
  const std::uint64_t clipped = lines::compensate(codes_row, scratch.first.data(), n, plans, scratch.shown.data(),
                                                  scratch.rho.data());
  FrameTally& t = out.tally;
  t.clipped += clipped;
  t.counts.beta_clipped += clipped;
  Raw* rho = scratch.rho.data();
  if (lcd_line) {
    scratch.shortfall.resize(n);
    emit_line(out, eye, y, scratch.shown.data(), scratch.shortfall.data());
    for (std::size_t s = 0; s < n; ++s) rho[s] += scratch.shortfall[s];
  } else {
    emit_line(out, eye, y, scratch.shown.data(), nullptr);
  }
  ResidualTally stored;
  scratch.residual_nonzero = lines::store_residuals(rho, n, kernels_, residual_row, stored);
  t.add(stored);
}

void FixedDecoderCore::reduced_line(FrameOutput& out, EyeState& eye, const Geometry& g, int y,
                                    const std::uint16_t* in0, const std::uint16_t* in1, const std::uint16_t* prev0,
                                    const std::uint16_t* prev1, const std::int32_t* residual_row,
                                    const ReducedLineGate* gate, bool grey, LineScratch& scratch) const {
  const int samples = 3 * g.full.width;
  const auto n = static_cast<std::size_t>(samples);
  const bool motion_static = gate != nullptr && gate->motion_static;
  const bool residual_zero = gate != nullptr && gate->residual_zero;
  const bool weight_unused = gate != nullptr && gate->weight_unused;
  const bool previous_needed =
      (residual_row != nullptr || residual_zero) && (gate == nullptr || gate->reads_previous());
  // The line kernels: the per-pixel steps keep the shown values, whose drive codes are then found over the line (an
  // LCD's by its drive kernel or emit: a reduced frame passes on no shortfall).
  const bool whole_line = line_values(out);
  const std::optional<MotionPlan>& motion = kernels_.line_plans().motion;
  if (whole_line && motion && (residual_row != nullptr || residual_zero)) {
    // Eqs. 4-6 over the line: w per pixel (1 on a static line, as reduced_pixel takes it), then alpha'. A line whose
    // stored residual is all zero takes the same kernels over zeros: w rho = 0 leaves clamp(alpha), what
    // clamp_alpha gives, and w still counts towards the mean-weight statistic.
    const auto pixels = static_cast<std::size_t>(g.full.width);
    const FixedLinePlans& plans = kernels_.line_plans();
    // Where nothing reads w and every U node lies in [0, 1], such a line's alpha' is alpha itself (the clamp is
    // never taken, and Eq. 4 adds nothing to the tally): on an OLED its codes are U's nodes' where the composed table
    // applies, else alpha is driven as it is.
    if (residual_zero && !previous_needed && plans.eotf->within_unit && codes_alone()) {
      const bool coded =
          blend_line_codes(in0, in1, g, y, plans, scratch.first_rows, out.frame.drive_codes.ptr<std::uint16_t>(y));
      if (!coded && narrow_lines(out)) {
        scratch.first32.resize(n);
        upsample(in0, in1, g, y, scratch.first32.data(), scratch.first_rows);
        emit_line(out, eye, y, scratch.first32.data(), nullptr);
      }
      if (coded || narrow_lines(out)) {
        if (motion_static) out.tally.weight_sum += kernels_.one() * static_cast<Raw>(pixels);
        return;
      }
    }
    if (residual_zero) {
      if (scratch.zero_residual.size() != n) scratch.zero_residual.assign(n, 0);
      residual_row = scratch.zero_residual.data();
    }
    scratch.weight.resize(pixels);
    MotionTally m;
    if (motion_static || weight_unused) {  // (an unused w: any value in [0, 1] gives clamp(alpha) over zeros)
      std::fill(scratch.weight.begin(), scratch.weight.end(), kernels_.one());
      m.weight_sum = motion_static ? kernels_.one() * static_cast<Raw>(pixels) : 0;
    }
    // Without the statistics w weighs only where rho is not 0 (elsewhere any w gives clamp(alpha)): the motion test,
    // and U of d_{t-1} before it, run on the runs of kMotionRunPixels pixels that hold such a sample (2 % of the
    // pixels of the panorama capture's lines with a residual lay in 14 % of its runs).
    const bool by_runs = !residual_zero && !config().motion_weight_statistics && skipping() &&
                         eye.residual_run_nonzero.size() ==
                             static_cast<std::size_t>(g.full.height) * motion_runs(g.full.width);
    // (the full frame's end_full_line kept its runs' flags where by_runs holds; the store is empty otherwise)
    const std::uint8_t* run_flags =
        by_runs ? eye.residual_run_nonzero.data() + static_cast<std::size_t>(y) * motion_runs(g.full.width) : nullptr;
    const auto runs_with_residual = [&](const auto& run) {
      for_each_motion_run(pixels, [&](std::size_t index, std::size_t x0, std::size_t x1) {
        if (run_flags[index] != 0) run(x0, x1);
      });
    };
    const auto weigh_run = [&](std::size_t x0, std::size_t x1) {
      blend_line(prev0, prev1, g, y, *plans.eotf, scratch.second_rows, scratch.second.data(), 3 * x0, 3 * x1);
      lines::motion_weights(scratch.second.data() + 3 * x0, scratch.first.data() + 3 * x0, x1 - x0, *motion,
                            kernels_, scratch.weight.data() + x0, m);
    };
    // Eq. 1's alpha and L_{t-1} from the stored d_{t-1} rows (64-bit lines: their kernels measured faster so), w,
    // and alpha' into 32-bit words where the OLED's drive search reads them (narrow_lines), else 64-bit ones.
    scratch.first.resize(n);
    scratch.second.resize(n);
    std::uint16_t* codes = out.frame.drive_codes.ptr<std::uint16_t>(y);
    if (by_runs && narrow_lines(out) && codes_alone() &&
        blend_line_codes(in0, in1, g, y, plans, scratch.first_rows, codes)) {
      // On an OLED with the composed table: the line's codes as if its residual were all zero (alpha' = alpha), then
      // alpha, w, Eq. 4 and the codes again on the runs that hold a residual.
      scratch.shown32.resize(n);
      runs_with_residual([&](std::size_t x0, std::size_t x1) {
        const std::size_t begin = 3 * x0;
        const std::size_t count = 3 * (x1 - x0);
        blend_line(in0, in1, g, y, *plans.eotf, scratch.first_rows, scratch.first.data(), begin, 3 * x1);
        if (previous_needed) weigh_run(x0, x1);
        lines::add_weighted_residuals(scratch.first.data() + begin, scratch.weight.data() + x0, residual_row + begin,
                                      count, *motion, kernels_, scratch.shown32.data() + begin, m);
        lines::drive_codes(scratch.shown32.data() + begin, count, *plans.drive, codes + begin);
      });
      if (previous_needed) ++out.tally.unweighed_lines;  // w of the other runs not measured
    } else {
      upsample(in0, in1, g, y, scratch.first.data(), grey, scratch.first_rows);
      if (previous_needed && by_runs) {
        std::fill(scratch.weight.begin(), scratch.weight.end(), kernels_.one());
        runs_with_residual(weigh_run);
        ++out.tally.unweighed_lines;  // w of the other runs not measured
      } else if (previous_needed) {
        upsample(prev0, prev1, g, y, scratch.second.data(), grey, scratch.second_rows);
        lines::motion_weights(scratch.second.data(), scratch.first.data(), pixels, *motion, kernels_,
                              scratch.weight.data(), m);
      }
      if (narrow_lines(out)) {
        scratch.shown32.resize(n);
        lines::add_weighted_residuals(scratch.first.data(), scratch.weight.data(), residual_row, n, *motion, kernels_,
                                      scratch.shown32.data(), m);
        emit_line(out, eye, y, scratch.shown32.data(), nullptr);
      } else {
        scratch.shown.resize(n);
        lines::add_weighted_residuals(scratch.first.data(), scratch.weight.data(), residual_row, n, *motion, kernels_,
                                      scratch.shown.data(), m);
        emit_line(out, eye, y, scratch.shown.data(), nullptr);
      }
    }
    FrameTally& t = out.tally;
    t.weight_sum += m.weight_sum;
    t.counts.weight_underflow += m.underflow;
    t.clipped += m.clipped;
    t.counts.alpha_clipped += m.clipped;
    t.dropped_sum += m.dropped_sum;
    t.residual_abs_sum += m.residual_abs_sum;
    t.residual_abs_max = std::max(t.residual_abs_max, m.residual_abs_max);
    return;
  }
  scratch.first.resize(n);
  upsample(in0, in1, g, y, scratch.first.data(), grey, scratch.first_rows);  // Eq. 1: alpha
  if (previous_needed) {  // L_{t-1} from the stored d_{t-1} rows
    scratch.second.resize(n);
    upsample(prev0, prev1, g, y, scratch.second.data(), grey, scratch.second_rows);
  }
  if (whole_line) scratch.shown.resize(n);
  Raw* shown = whole_line ? scratch.shown.data() : nullptr;
  for (int x = 0; x < g.full.width; ++x) {
    reduced_pixel(out, eye, y, x, scratch.first.data() + 3 * x,
                  previous_needed ? scratch.second.data() + 3 * x : nullptr, residual_row, gate, grey, shown);
  }
  if (whole_line) emit_line(out, eye, y, shown, nullptr);
}

template <typename Linear>
void FixedDecoderCore::report_line(FrameOutput& out, int y, const Linear* shown) const {
  const std::uint16_t* codes = out.frame.drive_codes.ptr<std::uint16_t>(y);
  double* wanted = out.frame.wanted_linear.ptr<double>(y);
  double* drive = out.frame.drive.ptr<double>(y);
  double* emitted = out.frame.emitted_linear.ptr<double>(y);
  const auto samples = 3 * static_cast<std::size_t>(out.frame.drive_codes.cols);
  const std::optional<DriveValuePlan>& plan = kernels_.line_plans().drive_value;
  // A chunk of whole pixels at a time, so that each chunk's samples start at red.
  constexpr std::size_t kChunk = 3 * 128;
  std::array<Raw, kChunk> drive_raw;
  for (std::size_t start = 0; start < samples; start += kChunk) {
    const std::size_t count = std::min(kChunk, samples - start);
    if (plan) {
      lines::drive_values(shown + start, count, *plan, kernels_, drive_raw.data());
    } else {
      for (std::size_t i = 0; i < count; ++i) {
        drive_raw[i] = kernels_.drive_value(shown[start + i], static_cast<int>(i % 3));
      }
    }
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = start + i;
      const int ch = static_cast<int>(i % 3);
      wanted[k] = kernels_.linear_to_double(shown[k]);
      drive[k] = kernels_.drive_to_double(drive_raw[i]);
      emitted[k] = kernels_.emitted(codes[k], 0, ch);
    }
  }
}

template <typename Linear>
void FixedDecoderCore::drive_lcd_line(FrameOutput& out, EyeState& eye, int y, const Linear* shown,
                                      Raw* shortfall) const {
  const auto samples = 3 * static_cast<std::size_t>(eye.full_size.width);
  const LcdPlan& plan = *kernels_.line_plans().lcd;
  std::uint8_t* previous_code = eye.lcd_previous_drive.ptr<std::uint8_t>(y);
  std::int32_t* previous_linear = eye.lcd_previous_linear.ptr<std::int32_t>(y);
  std::uint16_t* codes = out.frame.drive_codes.ptr<std::uint16_t>(y);
  if (!config().decoder.report_planes) {
    out.tally.counts.lcd_unreachable += lines::lcd_drive(shown, samples, plan, kernels_, previous_code,
                                                         previous_linear, out.lcd_held, codes, shortfall);
    return;
  }
  // The planes' drive value and light read v_{t-1} and x_{t-1}, which the kernel replaces in the frame stores: a
  // chunk of whole pixels at a time, its stored values kept.
  double* wanted = out.frame.wanted_linear.ptr<double>(y);
  double* drive = out.frame.drive.ptr<double>(y);
  double* emitted = out.frame.emitted_linear.ptr<double>(y);
  constexpr std::size_t kChunk = 3 * 128;
  std::array<std::uint8_t, kChunk> code_before;
  std::array<std::int32_t, kChunk> linear_before;
  std::array<Raw, kChunk> drive_raw;
  std::array<std::uint16_t, kChunk> solved_against;  // v_{t-1} of each merge (the held code on the first frame)
  for (std::size_t start = 0; start < samples; start += kChunk) {
    const std::size_t count = std::min(kChunk, samples - start);
    std::copy_n(previous_code + start, count, code_before.data());
    std::copy_n(previous_linear + start, count, linear_before.data());
    out.tally.counts.lcd_unreachable +=
        lines::lcd_drive(shown + start, count, plan, kernels_, previous_code + start, previous_linear + start,
                         out.lcd_held, codes + start, shortfall != nullptr ? shortfall + start : nullptr);
    kernels_.lcd_reports(shown + start, linear_before.data(), code_before.data(), codes + start, count,
                         out.lcd_held, drive_raw.data(), solved_against.data());
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = start + i;
      wanted[k] = kernels_.linear_to_double(shown[k]);
      drive[k] = kernels_.drive_to_double(drive_raw[i]);
      emitted[k] = kernels_.emitted(codes[k], solved_against[i], static_cast<int>(i % 3));
    }
  }
}

template <typename Linear>
bool FixedDecoderCore::drive_line(FrameOutput& out, EyeState& eye, int y, const Linear* shown, Raw* shortfall) const {
  const FixedLinePlans& plans = kernels_.line_plans();
  if (plans.drive) {
    const auto samples = 3 * static_cast<std::size_t>(eye.full_size.width);
    lines::drive_codes(shown, samples, *plans.drive, out.frame.drive_codes.ptr<std::uint16_t>(y));
    if (shortfall != nullptr) std::fill_n(shortfall, samples, Raw{0});
    if (config().decoder.report_planes) report_line(out, y, shown);
    return true;
  }
  if (!plans.lcd) return false;
  drive_lcd_line(out, eye, y, shown, shortfall);
  return true;
}

void FixedDecoderCore::emit_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* shown,
                                 Raw* shortfall) const {
  drive_line(out, eye, y, shown, shortfall);  // narrow_lines: one of the kernels runs
}

void FixedDecoderCore::emit_line(FrameOutput& out, EyeState& eye, int y, const Raw* shown, Raw* shortfall) const {
  if (drive_line(out, eye, y, shown, shortfall)) return;
  for (int x = 0; x < eye.full_size.width; ++x) {
    for (int ch = 0; ch < 3; ++ch) {
      const Raw missing = emit(out, eye, y, x, ch, shown[3 * x + ch]);
      if (shortfall != nullptr) shortfall[3 * x + ch] = missing;
    }
  }
}

void FixedDecoderCore::full_pixel(FrameOutput& out, EyeState& eye, int y, int x, const std::uint16_t* codes_row,
                                  const Raw* low, std::int32_t* residual_row, bool lost, bool grey) const {
  FrameTally& t = out.tally;
  Raw low_linear = 0;
  Raw full_linear = 0;
  CompensatedSample s;
  for (int ch = 0; ch < 3; ++ch) {
    if (ch == 0 || !grey) {
      low_linear = low[ch];                                          // L_t
      full_linear = kernels_.linear_of_code(codes_row[3 * x + ch]);  // I_t
      // Eq. 2; a lost line has no trustworthy beta and shows L_t (within [0, 1], so its rho is 0).
      s = lost ? kernels_.split(low_linear) : kernels_.compensate(full_linear, low_linear);
    }
    if (out.taps != nullptr) {
      tap(out, Stage::Linear, y, x, ch, full_linear);
      tap(out, Stage::LowPass, y, x, ch, low_linear);
      tap(out, Stage::Beta, y, x, ch, s.shown + s.rho);
      tap(out, Stage::Shown, y, x, ch, s.shown);
    }
    t.clipped += s.clipped ? 1 : 0;
    t.counts.beta_clipped += s.clipped ? 1 : 0;
    // LCD: an unreachable drive's shortfall joins rho (Sec. 4.4) before the residual store.
    const Raw shortfall = emit(out, eye, y, x, ch, s.shown);
    const StoredResidual stored = kernels_.store_residual(s.rho + shortfall);
    residual_row[3 * x + ch] = static_cast<std::int32_t>(stored.value);
    tap(out, Stage::Residual, y, x, ch, stored.value);
    ResidualTally residual;
    residual.add(stored);
    t.add(residual);
  }
}

void FixedDecoderCore::start_full_lines(EyeState& eye, const Geometry& g) const {
  if (!skipping()) return;
  eye.residual_nonzero.assign(static_cast<std::size_t>(g.full.height), 0);
  eye.residual_run_nonzero.assign(static_cast<std::size_t>(g.full.height) * motion_runs(g.full.width), 0);
  eye.residual_grey.assign(static_cast<std::size_t>(g.full.height), 0);
  eye.low_grey.assign(static_cast<std::size_t>(g.reduced.height), 0);
}

void FixedDecoderCore::end_full_line(FrameOutput& out, EyeState& eye, int y, const std::int32_t* residual_row,
                                     const LineScratch& scratch) const {
  if (!skipping()) return;
  // The OR of the line's residual samples, accumulated as they are produced (one flip-flop) and kept as the line's
  // flag: a line held all zero is not written to the store. It is the OR of the line's runs' flags (each the OR of the
  // run's samples), and a line its store kernel found all zero is not read again (its runs keep the 0 that
  // start_full_lines gave them).
  bool nonzero = false;
  if (scratch.residual_nonzero.value_or(true)) {
    const auto pixels = static_cast<std::size_t>(eye.full_size.width);
    std::uint8_t* runs = eye.residual_run_nonzero.data() + static_cast<std::size_t>(y) * motion_runs(eye.full_size.width);
    for_each_motion_run(pixels, [&](std::size_t index, std::size_t x0, std::size_t x1) {
      runs[index] = any_nonzero(residual_row + 3 * x0, 3 * (x1 - x0)) ? 1 : 0;
      nonzero = nonzero || runs[index] != 0;
    });
  }
  eye.residual_nonzero[static_cast<std::size_t>(y)] = nonzero ? 1 : 0;
  // The residual line's grey flag (R = G = B in every stored rho: an LCD shortfall can differ per channel); a line
  // all zero is grey without a second read.
  const bool grey = !nonzero || FixedKernels::grey_line(residual_row, eye.full_size.width);
  eye.residual_grey[static_cast<std::size_t>(y)] = grey ? 1 : 0;
  out.tally.counts.residual_write_lines_skipped += nonzero ? 0 : 1;
}

void FixedDecoderCore::reduced_pixel(FrameOutput& out, EyeState& eye, int y, int x, const Raw* alpha,
                                     const Raw* previous_low, const std::int32_t* residual_row,
                                     const ReducedLineGate* gate, bool grey, Raw* shown_line) const {
  const auto show = [&](int ch, Raw value) {
    if (shown_line != nullptr) {
      shown_line[3 * x + ch] = value;
    } else {
      emit(out, eye, y, x, ch, value);
    }
  };
  for (int ch = 0; ch < 3; ++ch) tap(out, Stage::Alpha, y, x, ch, alpha[ch]);
  const bool motion_static = gate != nullptr && gate->motion_static;
  const bool residual_zero = gate != nullptr && gate->residual_zero;
  if (residual_row == nullptr && !residual_zero) {
    // No full frame just before: alpha alone (U of codes stays within [0, 1]; the clamp only guards).
    for (int ch = 0; ch < 3; ++ch) {
      const Raw shown = std::clamp(alpha[ch], Raw{0}, kernels_.one());
      tap(out, Stage::AlphaPrime, y, x, ch, shown);
      show(ch, shown);
    }
    return;
  }
  // L_{t-1} for the motion test, from the stored d_{t-1}: the low-pass the full frame compensated against, bit for
  // bit (d_t rounds exact ties up, as the encoder's reduced frame does, so for static content it is the received i).
  // Static line (DESIGN §7): the d_{t-1} rows equal the received ones, so U of them is alpha.
  const Raw* previous = motion_static ? alpha : previous_low;
  FrameTally& t = out.tally;
  bool underflow = false;
  // An unused w (no residual, no motion statistics: a gate only without taps) is neither computed nor counted.
  const bool weight_unused = gate != nullptr && gate->weight_unused;
  const Raw weight = motion_static || weight_unused
                         ? kernels_.one()  // c = 0: w = 1 exactly (DESIGN §4)
                         : kernels_.motion_weight(kernels_.luma(previous), kernels_.luma(alpha), underflow);
  if (out.taps != nullptr) {
    for (int ch = 0; ch < 3; ++ch) tap(out, Stage::PreviousLowPass, y, x, ch, previous[ch]);
    tap(out, Stage::Contrast, y, x, 0, kernels_.motion_contrast(kernels_.luma(previous), kernels_.luma(alpha)));
    tap(out, Stage::Weight, y, x, 0, weight);
  }
  if (!weight_unused) t.weight_sum += weight;
  t.counts.weight_underflow += underflow ? 1 : 0;
  WeightedSample s;
  for (int ch = 0; ch < 3; ++ch) {
    const Raw residual = residual_zero ? 0 : residual_row[3 * x + ch];
    if (ch == 0 || !grey) {
      s = residual_zero ? kernels_.clamp_alpha(alpha[ch])
                        : kernels_.add_weighted_residual(alpha[ch], weight, residual);  // Eq. 4
    }
    t.clipped += s.clipped ? 1 : 0;
    t.counts.alpha_clipped += s.clipped ? 1 : 0;
    t.dropped_sum += s.dropped;
    const Raw magnitude = residual < 0 ? -residual : residual;
    t.residual_abs_sum += magnitude;
    t.residual_abs_max = std::max(t.residual_abs_max, magnitude);
    tap(out, Stage::AlphaPrime, y, x, ch, s.alpha_prime);
    show(ch, s.alpha_prime);
  }
}

void FixedDecoderCore::start_taps(FrameOutput& out, FixedStageTaps& taps, const Geometry& g, bool full,
                                  bool residual) const {
  const FixedDecoderConfig& c = config();
  const int F = c.linear_frac_bits;
  const int b = c.decoder.link.bits;
  const std::string linear = "uQ1." + std::to_string(F);
  taps = FixedStageTaps();
  const auto add = [&](Stage stage, const std::string& format, int bits, bool is_signed,
                       cv::Size size, int channels) {
    FixedStagePlane& p = taps[stage];
    p.present = true;
    p.name = stage_name(stage);
    p.format = format;
    p.bits = bits;
    p.is_signed = is_signed;
    p.size = size;
    p.channels = channels;
    p.values.assign(static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height) * static_cast<std::size_t>(channels), 0);
  };
  const std::string code = "uQ" + std::to_string(b) + ".0";
  add(Stage::Codes, code, b, false, full ? g.full : g.reduced, 3);
  if (full) {
    add(Stage::Linear, linear, 1 + F, false, g.full, 3);
    add(Stage::Reduced, code, b, false, g.reduced, 3);
    add(Stage::LowPass, linear, 1 + F, false, g.full, 3);
    add(Stage::Beta, "sQ3." + std::to_string(F), 3 + F, true, g.full, 3);
    add(Stage::Shown, linear, 1 + F, false, g.full, 3);
    add(Stage::Residual, std::string("sQ") + std::to_string(c.residual.int_bits) + "." + std::to_string(c.residual.frac_bits),
        c.residual.width(), true, g.full, 3);
  } else {
    add(Stage::Alpha, linear, 1 + F, false, g.full, 3);
    if (residual) {
      add(Stage::PreviousLowPass, linear, 1 + F, false, g.full, 3);
      add(Stage::Contrast, linear, 1 + F, false, g.full, 1);
      add(Stage::Weight, linear, 1 + F, false, g.full, 1);
    }
    add(Stage::AlphaPrime, linear, 1 + F, false, g.full, 3);
  }
  const int o = c.decoder.output_bits;
  add(Stage::Drive, "uQ" + std::to_string(o) + ".0", o, false, g.full, 3);
  out.taps = &taps;
}

DecodedFrame FixedDecoderCore::finish(FrameOutput&& out, EyeState& eye, bool full, bool residual_applied) {
  const FrameTally& t = out.tally;
  const double samples = 3.0 * static_cast<double>(out.frame.drive_codes.total());
  FrameStats& stats = out.frame.stats;
  stats.concealed_lines = out.concealed_lines;
  stats.clipped_fraction = static_cast<double>(t.clipped) / samples;
  if (full || residual_applied) {
    stats.residual_mean_abs = kernels_.residual_to_double(t.residual_abs_sum) / samples;
    stats.residual_max_abs = kernels_.residual_to_double(t.residual_abs_max);
  }
  if (residual_applied) {
    stats.residual_applied = true;
    stats.dropped_sum = kernels_.linear_to_double(t.dropped_sum);
    stats.mean_motion_weight = t.unweighed_lines > 0 ? std::numeric_limits<double>::quiet_NaN()
                                                     : kernels_.linear_to_double(t.weight_sum) / (samples / 3.0);
  }
  stats.lcd_unreachable_fraction = static_cast<double>(t.counts.lcd_unreachable) / samples;
  last_counts_ = t.counts;
  eye.last_output = out.frame;  // the held-output store (drive codes), shared, as the reference keeps it
  return std::move(out.frame);
}

detail::Arrival FixedDecoderCore::classify(const LinkFrame& frame, std::span<const std::uint8_t> line_intact,
                                           detail::Concealment& out, const char* who) {
  const detail::Arrival arrival = detail::classify_arrival(frame, line_intact, out, who);
  if (arrival == detail::Arrival::Partial) out.substitute = detail::concealment_substitute(eyes_, frame);
  return arrival;
}

DecodedFrame FixedDecoderCore::decode_lost(const FrameMeta& meta, const char* who) {
  detail::check_lost_view(meta, who);
  last_counts_ = FixedStageCounts();
  return detail::hold_lost_view(eyes_[meta.eye], meta, config().decoder.report_planes);
}

}  // namespace trm::fixed_detail
