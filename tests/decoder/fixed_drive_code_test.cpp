// The OLED drive code of every output sample against its definition, recomputed here from the threshold ROM's rule
// (T_k = the light of drive (k - 1/2) / (2^o - 1), rounded up onto the uQ1.F grid; the code is the largest k with
// x >= T_k), from the decoder's own wanted linear value: whatever search finds it (binary, halving, or the index
// the simulation uses), the code is the ROM's. Panels with different gammas, 8- and 10-bit drive, scenes and noise.
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace trm {
namespace {

std::vector<std::int64_t> thresholds_of(const Panel& panel, int output_bits, int frac_bits, int ch) {
  const int top = (1 << output_bits) - 1;
  std::vector<std::int64_t> t(static_cast<std::size_t>(top) + 1, 0);
  for (int k = 1; k <= top; ++k) {
    t[static_cast<std::size_t>(k)] =
        static_cast<std::int64_t>(std::ceil(std::ldexp(panel.linear_from_drive((k - 0.5) / top, ch), frac_bits)));
  }
  return t;
}

TEST(FixedDriveCode, EveryOutputCodeIsTheThresholdRomsCode) {
  for (const char* panel_name : {"vive", "rift"}) {
    for (const int output_bits : {8, 10}) {
      for (const char* scene_name : {"discs", "zoneplate", "flash"}) {
        FixedDecoderConfig config;
        config.decoder.link.reduction = 0.5;
        config.decoder.panel = parse_panel(panel_name);
        config.decoder.output_bits = output_bits;
        const int F = config.linear_frac_bits;
        std::array<std::vector<std::int64_t>, 3> thresholds;
        for (int ch = 0; ch < 3; ++ch) {
          thresholds[static_cast<std::size_t>(ch)] = thresholds_of(config.decoder.panel, output_bits, F, ch);
        }
        SceneParams params;
        params.width = 64;
        params.height = 48;
        params.supersample = 1;
        const auto scene = make_scene(scene_name, params);
        const TrmEncoder encoder(config.decoder.link);
        FixedStreamingDecoder decoder(config);
        std::int64_t checked = 0;
        for (int t = 0; t < 4; ++t) {
          const DecodedFrame out = decoder.decode(encoder.encode(scene->linear_frame(t), t, 0));
          for (int y = 0; y < out.drive_codes.rows; ++y) {
            const double* wanted = out.wanted_linear.ptr<double>(y);
            const std::uint16_t* codes = out.drive_codes.ptr<std::uint16_t>(y);
            for (int k = 0; k < 3 * out.drive_codes.cols; ++k) {
              const auto x = static_cast<std::int64_t>(std::ldexp(wanted[k], F));  // exact: the raw uQ1.F value
              const std::vector<std::int64_t>& rom = thresholds[static_cast<std::size_t>(k % 3)];
              std::size_t expected = 0;
              while (expected + 1 < rom.size() && x >= rom[expected + 1]) ++expected;
              ASSERT_EQ(codes[k], expected) << panel_name << " " << output_bits << " bits " << scene_name << " t=" << t
                                            << " y=" << y << " sample " << k << " x=" << x;
              ++checked;
            }
          }
        }
        EXPECT_GT(checked, 0);
      }
    }
  }
}

}  // namespace
}  // namespace trm
