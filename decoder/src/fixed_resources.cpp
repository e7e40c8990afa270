// The hardware resources of the per-pixel stages: the ROMs of a configuration and the operator table per stage
// (DESIGN §5), reported by the hardware model.
#include "fixed_kernels.hpp"

#include <algorithm>
#include <string>

namespace trm::fixed_detail {

std::vector<FixedRomReport> FixedKernels::roms() const {
  const auto lut = [](const std::string& name, const fx::InterpolatedLut& table, int count = 1) {
    const fx::RomSize size = table.rom_size();
    return FixedRomReport{name, size.entries, size.word_bits, count};
  };
  const int F = config_.linear_frac_bits;
  const int top = max_output_code();
  std::vector<FixedRomReport> out;
  if (linear_space_) {
    const int P = config_.linear_resample_frac_bits;
    const int b = config_.decoder.link.bits;
    out.push_back({"I = lin(E), lin(d|i) for U: direct ROM per code (uQ1." + std::to_string(F) + ")",
                   static_cast<int>(code_rom_.size()), 1 + F, 1});
    out.push_back({"D input lin(E): direct ROM per link code (uQ1." + std::to_string(P) + ")",
                   static_cast<int>(resample_rom_.size()), 1 + P, 1});
    out.push_back({"D re-encoding to " + std::to_string(b) + "-bit link codes: thresholds T_k (uQ1." +
                       std::to_string(P) + ")",
                   static_cast<int>(encode_thresholds_.size()), 1 + P, 1});
  } else {
    out.push_back({"I = lin(E): direct ROM per link code (uQ1." + std::to_string(F) + ")",
                   static_cast<int>(code_rom_.size()), 1 + F, 1});
    out.push_back(lut("L, alpha = lin(U(.)): interpolated EOTF LUT", *eotf_));
  }
  out.push_back(lut("Eq. 5 1/(Yp + Ya): normalised reciprocal LUT", *reciprocal_));
  out.push_back({"Eq. 6 exp(-i), i = 0..15", static_cast<int>(exp_integer_rom_.size()), 1 + F, 1});
  out.push_back(lut("Eq. 6 exp(-f), f in [0, 1): interpolated LUT", *exp_fraction_));
  if (lcd_) {
    out.push_back(lut("LCD target m = x^(1/gamma): octave-segmented LUT", *lcd_target_lut_));
    out.push_back({"LCD M(0|1, v_{t-1})^gamma: clamped-drive luminance ROMs (sQ4." + std::to_string(F) + ")",
                   top + 1, 4 + F, 2});
  } else {
    // The drive value LUT (DecodedFrame::drive) feeds reports only; the drive codes come from the thresholds.
    out.push_back({"OLED drive thresholds T_k per channel (uQ1." + std::to_string(F) + ")", top + 1, 1 + F, 3});
  }
  return out;
}

// Operators per evaluation of each stage, counted from the functions above (worst case per evaluation; a
// rounding "+ half LSB" before a shift counts as an adder, a clamp as two comparators, a shift or a bit-field
// extraction as nothing). A rare path is left out: the LCD held first frame (a second search).
//
// | stage                          | per            | adders            | multipliers | comparators | ROM reads |
// |--------------------------------|----------------|-------------------|-------------|-------------|-----------|
// | I = lin(E)                     | sample         | 0                 | 0           | 0           | 1         |
// | D horizontal (n_h taps)        | reduced sample | n_h               | n_h         | 1 (RndConv) | 0         |
// | D vertical + Q_b (n_v taps)    | reduced sample | n_v               | n_v         | 0           | 0         |
// | U bilinear (blend)             | sample         | 6                 | 6           | 0           | 0         |
// | EOTF LUT (interpolated)        | sample         | 3                 | 1           | 0           | 2         |
// | Eq. 2 beta, clamp, rho         | sample         | 2                 | 0           | 2           | 0         |
// | residual store (round, sat.)   | sample         | 1                 | 0           | 2           | 0         |
// | luma of L_{t-1} and alpha      | pixel          | 6                 | 6           | 0           | 0         |
// | Eq. 5 contrast c               | pixel          | 6                 | 2           | 3           | 2         |
// | Eq. 6 weight w                 | pixel          | 5                 | 3           | 1           | 3         |
// | Eq. 4 alpha'                   | sample         | 2                 | 1           | 2           | 0         |
// | OLED drive code (search)       | sample         | 0                 | 0           | o           | o         |
// | LCD drive code (Eq. 7 inverse) | sample         | 4 + 6 o           | 2 + 8 o     | 2 + o       | 4         |
//
// In the linear resample space D reads lin(E) from a ROM per tap and re-encodes through the threshold ROM, U reads
// lin(code) from the I ROM per corner, and there is no EOTF LUT:
//
// | D horizontal on lin(E) (n_h)   | reduced sample | n_h               | n_h         | 0           | n_h       |
// | D vertical + re-encoding (n_v) | reduced sample | n_v               | n_v         | b           | b         |
// | U bilinear of lin(.)           | sample         | 6                 | 6           | 0           | 4         |
std::vector<FixedArithmeticReport> FixedKernels::arithmetic(const Geometry& g) const {
  const auto widest = [](const std::vector<PolyphaseTaps>& axis) {
    std::size_t n = 0;
    for (const auto& taps : axis) n = std::max(n, taps.weight.size());
    return static_cast<int>(n);
  };
  const int n_h = widest(g.gauss_cols);
  const int n_v = widest(g.gauss_rows);
  const int o = config_.decoder.output_bits;
  const std::int64_t pixels = static_cast<std::int64_t>(g.full.width) * g.full.height;
  const std::int64_t samples = 3 * pixels;
  const std::int64_t horizontal = 3 * static_cast<std::int64_t>(g.reduced.width) * g.full.height;
  const std::int64_t vertical = 3 * static_cast<std::int64_t>(g.reduced.width) * g.reduced.height;
  std::vector<FixedArithmeticReport> out;
  if (linear_space_) {
    const int b = config_.decoder.link.bits;
    out = {
        {"I = lin(E)", "full", "channel sample", samples, 0, 0, 0, 1},
        {"D horizontal on lin(E) (" + std::to_string(n_h) + " taps)", "full", "reduced-width sample per input line",
         horizontal, n_h, n_h, 0, n_h},
        {"D vertical + re-encode (" + std::to_string(n_v) + " taps, " + std::to_string(b) + " steps)", "full",
         "reduced sample", vertical, n_v, n_v, b, b},
        {"U bilinear of lin(d_t): L", "full", "channel sample", samples, 6, 6, 0, 4},
        {"Eq. 2 beta = 2I - L, shown, rho", "full", "channel sample", samples, 2, 0, 2, 0},
        {"residual store (round, saturate)", "full", "channel sample", samples, 1, 0, 2, 0},
        {"U bilinear of lin(i): alpha", "reduced", "channel sample", samples, 6, 6, 0, 4},
        {"U bilinear of lin(d_{t-1}): L_{t-1}", "reduced", "channel sample", samples, 6, 6, 0, 4},
        {"luma of L_{t-1} and alpha", "reduced", "pixel", pixels, 6, 6, 0, 0},
        {"Eq. 5 motion contrast c", "reduced", "pixel", pixels, 6, 2, 3, 2},
        {"Eq. 6 weight w = exp(-s c)", "reduced", "pixel", pixels, 5, 3, 1, 3},
        {"Eq. 4 alpha' = clamp(alpha + w rho)", "reduced", "channel sample", samples, 2, 1, 2, 0},
    };
  } else {
    out = {
        {"I = lin(E)", "full", "channel sample", samples, 0, 0, 0, 1},
        {"D horizontal (" + std::to_string(n_h) + " taps)", "full", "reduced-width sample per input line", horizontal,
         n_h, n_h, 1, 0},
        {"D vertical + Q_b (" + std::to_string(n_v) + " taps)", "full", "reduced sample", vertical, n_v, n_v, 0, 0},
        {"U bilinear of d_t", "full", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: L = lin(U(d_t))", "full", "channel sample", samples, 3, 1, 0, 2},
        {"Eq. 2 beta = 2I - L, shown, rho", "full", "channel sample", samples, 2, 0, 2, 0},
        {"residual store (round, saturate)", "full", "channel sample", samples, 1, 0, 2, 0},
        {"U bilinear of i", "reduced", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: alpha = lin(U(i))", "reduced", "channel sample", samples, 3, 1, 0, 2},
        {"U bilinear of d_{t-1}", "reduced", "channel sample", samples, 6, 6, 0, 0},
        {"EOTF LUT: L_{t-1} = lin(U(d_{t-1}))", "reduced", "channel sample", samples, 3, 1, 0, 2},
        {"luma of L_{t-1} and alpha", "reduced", "pixel", pixels, 6, 6, 0, 0},
        {"Eq. 5 motion contrast c", "reduced", "pixel", pixels, 6, 2, 3, 2},
        {"Eq. 6 weight w = exp(-s c)", "reduced", "pixel", pixels, 5, 3, 1, 3},
        {"Eq. 4 alpha' = clamp(alpha + w rho)", "reduced", "channel sample", samples, 2, 1, 2, 0},
    };
  }
  if (lcd_) {
    out.push_back({"LCD drive code (Eq. 7 inverse, " + std::to_string(o) + "-step search)", "both", "channel sample",
                   samples, 4 + 6 * o, 2 + 8 * o, 2 + o, 4});
  } else {
    out.push_back({"OLED drive code (" + std::to_string(o) + "-step threshold search)", "both", "channel sample",
                   samples, 0, 0, o, o});
  }
  return out;
}

}  // namespace trm::fixed_detail
