// Prints the LUT accuracy table of docs/fixed_point.md (markdown). Every representable input code
// of each table is evaluated and compared with the std:: function:
//   * max |lut − Q(f)| in output LSB, with Q(f) the exact function rounded to nearest in the output
//     format (the figure the tests bound);
//   * max |lut − f| in output LSB (real-valued error, includes the final rounding);
//   * error-free bits: floor(−log2(max |lut − f|)) in absolute units (ac_math's convention).
// Regenerate with:  cmake --build <build> --target lut_accuracy && <build>/tests/fixed_point/lut_accuracy
#include "lut_reference.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  using namespace trm::fx;
  const int sizes[] = {17, 33, 65, 257, 1025};
  std::printf("| function | segments | entries | ROM bits | max err vs Q(f) [LSB] | max err vs f [LSB] | error-free bits | monotonic |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|:---:|\n");
  for (const auto& function : testing::reference_functions()) {
    for (const int octaves : {0, 16}) {
    for (const int entries : sizes) {
      LutShape shape;  // 16-bit input, 16-bit output
      shape.entries = entries;
      shape.input_bits = 16;
      shape.output_bits = function.output_bits;
      shape.output_frac_bits = function.output_frac_bits;
      shape.octaves = octaves;
      const InterpolatedLut lut = function.make(shape);
      const testing::LutError e = testing::measure(lut, function.exact, function.direction);
      std::printf("| %s | %s | %d | %lld | %lld | %.3f | %d | %s |\n", function.label.c_str(),
                  octaves == 0 ? "uniform" : "16 octaves", entries,
                  static_cast<long long>(lut.rom_size().bits()), static_cast<long long>(e.max_lsb_vs_quantised),
                  e.max_lsb_vs_exact, e.error_free_bits, e.monotonic ? "yes" : "no");
    }
    }
  }
  return 0;
}
