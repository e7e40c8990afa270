// The fixed-point decoder's stage kernels one line at a time (2160-pixel lines, r = 1/2, default formats, vive OLED
// unless named), so that a change in decode time points at its stage. Items are channel samples of the stage's output
// (pixels for the per-pixel motion weight). The kernels are the schedules' own (fixed_kernels.hpp); the BM_Line*
// ones are the line kernels (fixed_lines.hpp) the streaming decoder runs at these formats, at the instruction set
// Highway dispatches to on this CPU (printed as the context's "line kernels"); D's two halves dispatch to theirs from
// gaussian_horizontal_line and gaussian_vertical_row.
#include "fixed_kernels.hpp"
#include "fixed_lines.hpp"

#include "trm/panel.hpp"

#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace {

using trm::fixed_detail::FixedKernels;
using trm::fixed_detail::Geometry;
using trm::fixed_detail::Raw;

constexpr int kWidth = 2160;
constexpr int kHeight = 1200;

trm::FixedDecoderConfig config_of(const char* panel) {
  trm::FixedDecoderConfig config;
  config.decoder.link.reduction = 0.5;
  config.decoder.panel = trm::parse_panel(panel);
  return config;
}

std::vector<std::uint16_t> random_codes(int samples, int top, std::uint64_t seed) {
  cv::RNG rng(seed);
  std::vector<std::uint16_t> codes(static_cast<std::size_t>(samples));
  for (std::uint16_t& c : codes) c = static_cast<std::uint16_t>(rng.uniform(0, top + 1));
  return codes;
}

std::vector<Raw> random_linear(int samples, Raw one, std::uint64_t seed) {
  cv::RNG rng(seed);
  std::vector<Raw> values(static_cast<std::size_t>(samples));
  for (Raw& v : values) v = static_cast<Raw>(rng.uniform(0.0, 1.0) * static_cast<double>(one));
  return values;
}

// D's halves into and from line buffers of 64-bit or 32-bit words (the streaming decoder's, where the values fit:
// FixedKernels::narrow_gaussian_lines).
template <typename Line>
void BM_GaussianHorizontal(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const std::vector<std::uint16_t> line = random_codes(3 * kWidth, kernels.max_code(), 1);
  std::vector<Line> out(static_cast<std::size_t>(3 * g.reduced.width));
  for (auto _ : state) {
    kernels.gaussian_horizontal_line(line.data(), g, out.data(), false);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * g.reduced.width);
}
BENCHMARK_TEMPLATE(BM_GaussianHorizontal, std::uint32_t);
BENCHMARK_TEMPLATE(BM_GaussianHorizontal, Raw);

// The same line one sample at a time (the per-sample function the line kernel replaced in the schedules).
void BM_GaussianHorizontalPerSample(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const std::vector<std::uint16_t> line = random_codes(3 * kWidth, kernels.max_code(), 1);
  std::vector<Raw> out(static_cast<std::size_t>(3 * g.reduced.width));
  for (auto _ : state) {
    for (int k = 0; k < g.reduced.width; ++k) {
      for (int ch = 0; ch < 3; ++ch) {
        out[static_cast<std::size_t>(3 * k + ch)] =
            kernels.gaussian_horizontal(line.data(), g.gauss_cols[static_cast<std::size_t>(k)], ch);
      }
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * g.reduced.width);
}
BENCHMARK(BM_GaussianHorizontalPerSample);

template <typename Line>
void BM_GaussianVertical(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const int samples = 3 * g.reduced.width;
  const auto& taps = g.gauss_rows[static_cast<std::size_t>(g.reduced.height / 2)];
  std::vector<std::vector<Line>> rows;
  std::vector<const Line*> pointers;
  for (std::size_t j = 0; j < taps.weight.size(); ++j) {
    const std::vector<Raw> values = random_linear(samples, Raw{255} << 16, 10 + j);
    rows.emplace_back(values.begin(), values.end());
  }
  for (const auto& r : rows) pointers.push_back(r.data());
  std::vector<std::uint16_t> out(static_cast<std::size_t>(samples));
  for (auto _ : state) {
    kernels.gaussian_vertical_row(pointers.data(), taps, samples, out.data(), false);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * samples);
}
BENCHMARK_TEMPLATE(BM_GaussianVertical, std::uint32_t);
BENCHMARK_TEMPLATE(BM_GaussianVertical, Raw);

// U of two reduced rows and the EOTF LUT after it: L or alpha of one output line.
void BM_UpsampleLinear(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const std::vector<std::uint16_t> row0 = random_codes(3 * g.reduced.width, kernels.max_code(), 2);
  const std::vector<std::uint16_t> row1 = random_codes(3 * g.reduced.width, kernels.max_code(), 3);
  const Raw row_upper = g.bilinear_rows[1].upper;
  std::vector<Raw> out(static_cast<std::size_t>(3 * kWidth));
  for (auto _ : state) {
    for (int x = 0; x < kWidth; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        out[static_cast<std::size_t>(3 * x + ch)] = kernels.linear_of_upsampled(
            kernels.upsample(row0.data(), row1.data(), g.bilinear_cols[static_cast<std::size_t>(x)], row_upper, ch));
      }
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_UpsampleLinear);

// Eq. 2 and the residual store: beta, shown, rho of one output line.
void BM_CompensateAndStore(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> full = random_linear(3 * kWidth, kernels.one(), 4);
  const std::vector<Raw> low = random_linear(3 * kWidth, kernels.one(), 5);
  std::vector<std::int32_t> residual(static_cast<std::size_t>(3 * kWidth));
  std::vector<Raw> shown(static_cast<std::size_t>(3 * kWidth));
  for (auto _ : state) {
    for (std::size_t k = 0; k < full.size(); ++k) {
      const auto s = kernels.compensate(full[k], low[k]);
      shown[k] = s.shown;
      residual[k] = static_cast<std::int32_t>(kernels.store_residual(s.rho).value);
    }
    benchmark::DoNotOptimize(residual.data());
    benchmark::DoNotOptimize(shown.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_CompensateAndStore);

// Eqs. 5-6 per pixel: luma of L_{t-1} and alpha, c through the reciprocal, w = exp(-s c).
void BM_MotionWeight(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> previous = random_linear(3 * kWidth, kernels.one(), 6);
  const std::vector<Raw> alpha = random_linear(3 * kWidth, kernels.one(), 7);
  std::vector<Raw> weight(static_cast<std::size_t>(kWidth));
  for (auto _ : state) {
    for (int x = 0; x < kWidth; ++x) {
      bool underflow = false;
      weight[static_cast<std::size_t>(x)] = kernels.motion_weight(
          kernels.luma(previous.data() + 3 * x), kernels.luma(alpha.data() + 3 * x), underflow);
    }
    benchmark::DoNotOptimize(weight.data());
  }
  state.SetItemsProcessed(state.iterations() * kWidth);
}
BENCHMARK(BM_MotionWeight);

// Eq. 4: alpha' = clamp(alpha + w rho).
void BM_AddWeightedResidual(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> alpha = random_linear(3 * kWidth, kernels.one(), 8);
  const std::vector<Raw> weight = random_linear(kWidth, kernels.one(), 9);
  const std::vector<Raw> residual = random_linear(3 * kWidth, kernels.one() / 4, 10);
  std::vector<Raw> out(static_cast<std::size_t>(3 * kWidth));
  for (auto _ : state) {
    for (std::size_t k = 0; k < out.size(); ++k) {
      out[k] = kernels.add_weighted_residual(alpha[k], weight[k / 3], residual[k]).alpha_prime;
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_AddWeightedResidual);

// OLED drive code (threshold ROM search) of one output line.
void BM_OledDriveCode(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> wanted = random_linear(3 * kWidth, kernels.one(), 11);
  std::vector<std::uint16_t> codes(wanted.size());
  for (auto _ : state) {
    for (std::size_t k = 0; k < wanted.size(); ++k) codes[k] = kernels.drive_code(wanted[k], static_cast<int>(k % 3));
    benchmark::DoNotOptimize(codes.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_OledDriveCode);

// The drive value v for reports (DecodedFrame::drive), not part of the hardware's output.
void BM_OledDriveValue(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> wanted = random_linear(3 * kWidth, kernels.one(), 12);
  std::vector<Raw> values(wanted.size());
  for (auto _ : state) {
    for (std::size_t k = 0; k < wanted.size(); ++k) values[k] = kernels.drive_value(wanted[k], static_cast<int>(k % 3));
    benchmark::DoNotOptimize(values.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_OledDriveValue);

// LCD drive (Eq. 7 inverse against v_{t-1}) of one output line. Arg: 1 = also the report drive value v (what the
// decoder computes with report planes), 0 = the code alone.
void BM_LcdDrive(benchmark::State& state) {
  const bool drive_value = state.range(0) != 0;
  FixedKernels kernels(config_of("lcd"));
  const std::vector<Raw> wanted = random_linear(3 * kWidth, kernels.one(), 13);
  const std::vector<Raw> previous = random_linear(3 * kWidth, kernels.one(), 14);
  const std::vector<std::uint16_t> previous_codes = random_codes(3 * kWidth, kernels.max_output_code(), 15);
  std::vector<std::uint16_t> codes(wanted.size());
  for (auto _ : state) {
    for (std::size_t k = 0; k < wanted.size(); ++k) {
      codes[k] = kernels.lcd_drive(wanted[k], previous[k], previous_codes[k], false, drive_value).code;
    }
    benchmark::DoNotOptimize(codes.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_LcdDrive)->Arg(0)->Arg(1);

// Printed once in the context block: the instruction set the line kernels dispatch to.
const bool kLineKernelContext = [] {
  benchmark::AddCustomContext("line kernels", trm::fixed_detail::lines::target_name());
  return true;
}();

// The line kernels: U's column blend of two reduced rows and the row blend with the EOTF (one output line of L or
// alpha, the column blends not cached), Eq. 2's split, Eqs. 5-6 per pixel, Eq. 4 and the OLED drive codes.
void BM_LineUpsampleEotf(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const std::vector<std::uint16_t> row0 = random_codes(3 * g.reduced.width, kernels.max_code(), 2);
  const std::vector<std::uint16_t> row1 = random_codes(3 * g.reduced.width, kernels.max_code(), 3);
  const auto n = static_cast<std::size_t>(3 * kWidth);
  std::vector<std::uint32_t> top(n), bottom(n);
  std::vector<Raw> out(n);
  for (auto _ : state) {
    trm::fixed_detail::lines::blend_columns(row0.data(), g.column_blend, n, top.data());
    trm::fixed_detail::lines::blend_columns(row1.data(), g.column_blend, n, bottom.data());
    trm::fixed_detail::lines::blend_rows_eotf(top.data(), bottom.data(), n,
                                              static_cast<std::uint32_t>(g.bilinear_rows[1].upper),
                                              g.column_blend.weight_bits, *kernels.line_plans().eotf, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_LineUpsampleEotf);

// U's two halves apart: the column blend of one reduced row (run once per reduced row and cached for the two output
// lines that read it) and the row blend with the EOTF (once per output line and pass).
void BM_LineBlendColumns(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const std::vector<std::uint16_t> row = random_codes(3 * g.reduced.width, kernels.max_code(), 2);
  const auto n = static_cast<std::size_t>(3 * kWidth);
  std::vector<std::uint32_t> out(n);
  for (auto _ : state) {
    trm::fixed_detail::lines::blend_columns(row.data(), g.column_blend, n, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_LineBlendColumns);

// Into a 32-bit line (an OLED full frame's L_t, `<int>`) or a 64-bit one (alpha and L_{t-1}, and every LCD line,
// `<long>`); Eq. 2 and the drive codes below likewise (OLED `<int>`). Arg: 0 = as the decoder runs it at r = 1/2
// (quarter weights: the exact blend, one node per sample), 1 = the ROM interpolation every other r takes.
// The column blends of two random reduced rows: the row blend's top and bottom operands.
struct ColumnBlends {
  ColumnBlends(const FixedKernels& kernels, const Geometry& g) {
    trm::fixed_detail::lines::blend_columns(random_codes(3 * g.reduced.width, kernels.max_code(), 2).data(),
                                            g.column_blend, top.size(), top.data());
    trm::fixed_detail::lines::blend_columns(random_codes(3 * g.reduced.width, kernels.max_code(), 3).data(),
                                            g.column_blend, bottom.size(), bottom.data());
  }
  std::vector<std::uint32_t> top = std::vector<std::uint32_t>(3 * static_cast<std::size_t>(kWidth));
  std::vector<std::uint32_t> bottom = std::vector<std::uint32_t>(3 * static_cast<std::size_t>(kWidth));
};

template <typename Line>
void BM_LineBlendRowsEotf(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const int column_bits = state.range(0) == 0 ? g.column_blend.weight_bits : 31;
  const auto n = static_cast<std::size_t>(3 * kWidth);
  const ColumnBlends blends(kernels, g);
  const std::vector<std::uint32_t>& top = blends.top;
  const std::vector<std::uint32_t>& bottom = blends.bottom;
  std::vector<Line> out(n);
  for (auto _ : state) {
    trm::fixed_detail::lines::blend_rows_eotf(top.data(), bottom.data(), n,
                                              static_cast<std::uint32_t>(g.bilinear_rows[1].upper), column_bits,
                                              *kernels.line_plans().eotf, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK_TEMPLATE(BM_LineBlendRowsEotf, std::int32_t)->Arg(0)->Arg(1);
BENCHMARK_TEMPLATE(BM_LineBlendRowsEotf, Raw)->Arg(0)->Arg(1);

// The exact row blend straight into drive codes (a reduced line whose stored residual is all zero, where nothing reads
// w): what replaces the row blend, Eq. 4 and the drive search there.
void BM_LineBlendRowsDrive(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const Geometry& g = kernels.geometry(cv::Size(kWidth, kHeight));
  const auto n = static_cast<std::size_t>(3 * kWidth);
  const ColumnBlends blends(kernels, g);
  const std::vector<std::uint32_t>& top = blends.top;
  const std::vector<std::uint32_t>& bottom = blends.bottom;
  std::vector<std::uint16_t> codes(n);
  for (auto _ : state) {
    const bool exact = trm::fixed_detail::lines::blend_rows_drive(
        top.data(), bottom.data(), n, static_cast<std::uint32_t>(g.bilinear_rows[1].upper), g.column_blend.weight_bits,
        *kernels.line_plans().eotf, kernels.line_plans().drive_of_node, codes.data());
    if (!exact) {
      state.SkipWithError("the exact path does not apply");
      break;
    }
    benchmark::DoNotOptimize(codes.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK(BM_LineBlendRowsDrive);

// A line of random linear values in [0, limit] in the line kernels' words.
template <typename Line>
std::vector<Line> random_line(std::size_t n, Raw limit, unsigned seed) {
  const std::vector<Raw> values = random_linear(n, limit, seed);
  return std::vector<Line>(values.begin(), values.end());
}

template <typename Line>
void BM_LineCompensate(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<std::uint16_t> codes = random_codes(3 * kWidth, kernels.max_code(), 4);
  const std::vector<Line> low = random_line<Line>(3 * kWidth, kernels.one(), 5);
  std::vector<Line> shown(codes.size()), rho(codes.size());
  const auto& plans = kernels.line_plans();
  for (auto _ : state) {
    benchmark::DoNotOptimize(trm::fixed_detail::lines::compensate(codes.data(), low.data(), codes.size(), plans,
                                                                  shown.data(), rho.data()));
    benchmark::DoNotOptimize(rho.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK_TEMPLATE(BM_LineCompensate, std::int32_t);
BENCHMARK_TEMPLATE(BM_LineCompensate, Raw);

void BM_LineMotionWeights(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> previous = random_linear(3 * kWidth, kernels.one(), 6);
  const std::vector<Raw> alpha = random_linear(3 * kWidth, kernels.one(), 7);
  std::vector<Raw> weight(static_cast<std::size_t>(kWidth));
  for (auto _ : state) {
    trm::fixed_detail::MotionTally tally;
    trm::fixed_detail::lines::motion_weights(previous.data(), alpha.data(), weight.size(), *kernels.line_plans().motion,
                                             kernels, weight.data(), tally);
    benchmark::DoNotOptimize(weight.data());
  }
  state.SetItemsProcessed(state.iterations() * kWidth);
}
BENCHMARK(BM_LineMotionWeights);

// alpha' into a 32-bit line (the OLED's, `<int>`) or a 64-bit one (the LCD's, `<long>`).
template <typename Shown>
void BM_LineAddWeightedResiduals(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Raw> alpha = random_linear(3 * kWidth, kernels.one(), 8);
  const std::vector<Raw> weight = random_linear(kWidth, kernels.one(), 9);
  const std::vector<Raw> wide_residual = random_linear(3 * kWidth, kernels.one() / 4, 10);
  const std::vector<std::int32_t> residual(wide_residual.begin(), wide_residual.end());
  std::vector<Shown> out(alpha.size());
  for (auto _ : state) {
    trm::fixed_detail::MotionTally tally;
    trm::fixed_detail::lines::add_weighted_residuals(alpha.data(), weight.data(), residual.data(), out.size(),
                                                     *kernels.line_plans().motion, kernels, out.data(), tally);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK_TEMPLATE(BM_LineAddWeightedResiduals, std::int32_t);
BENCHMARK_TEMPLATE(BM_LineAddWeightedResiduals, Raw);

template <typename Line>
void BM_LineOledDriveCodes(benchmark::State& state) {
  FixedKernels kernels(config_of("vive"));
  const std::vector<Line> wanted = random_line<Line>(3 * kWidth, kernels.one(), 11);
  std::vector<std::uint16_t> codes(wanted.size());
  for (auto _ : state) {
    trm::fixed_detail::lines::drive_codes(wanted.data(), wanted.size(), *kernels.line_plans().drive, codes.data());
    benchmark::DoNotOptimize(codes.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK_TEMPLATE(BM_LineOledDriveCodes, std::int32_t);
BENCHMARK_TEMPLATE(BM_LineOledDriveCodes, Raw);

// The LCD drive over a line after the eye's first frame, with its frame-store update (the stores are rewritten each
// iteration from the same random history, outside the timing). Random rows v_{t-1}: every lookup far from the last.
template <typename Linear>
void BM_LineLcdDrive(benchmark::State& state) {
  FixedKernels kernels(config_of("lcd"));
  const std::vector<Raw> wide = random_linear(3 * kWidth, kernels.one(), 13);
  const std::vector<Linear> wanted(wide.begin(), wide.end());
  const std::vector<Raw> previous = random_linear(3 * kWidth, kernels.one(), 14);
  const std::vector<std::uint16_t> previous_codes = random_codes(3 * kWidth, kernels.max_output_code(), 15);
  std::vector<std::int32_t> store_linear(previous.size());
  std::vector<std::uint8_t> store_codes(previous_codes.size());  // the 8-bit v_{t-1} store
  std::vector<std::uint16_t> codes(wanted.size());
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(previous.begin(), previous.end(), store_linear.begin());
    std::copy(previous_codes.begin(), previous_codes.end(), store_codes.begin());
    state.ResumeTiming();
    benchmark::DoNotOptimize(trm::fixed_detail::lines::lcd_drive(wanted.data(), wanted.size(), *kernels.line_plans().lcd,
                                                                 kernels, store_codes.data(), store_linear.data(),
                                                                 false, codes.data(), nullptr));
    benchmark::DoNotOptimize(codes.data());
  }
  state.SetItemsProcessed(state.iterations() * 3 * kWidth);
}
BENCHMARK_TEMPLATE(BM_LineLcdDrive, std::int32_t);
BENCHMARK_TEMPLATE(BM_LineLcdDrive, Raw);

}  // namespace
