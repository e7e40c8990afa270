// The fixed-point decoders in the linear resample space (D and U on linear light, as the encoder's
// Q_b(enc(D(lin(E))))): the two schedules agree bit for bit, d_t reproduces the encoder's reduced frame, and the
// output agrees with the double reference as in the encoded space (DESIGN §6).
#include "fixed_decoder_test_support.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::fixed_config;
using test::link_config;
using test::noise_images;
using test::scene_images;

constexpr ResampleSpace kLinear = ResampleSpace::Linear;

std::string r_text(double r) { return std::to_string(r).substr(0, 4); }

TEST(FixedLinearSpace, StreamingMatchesFrameOnEveryScene) {
  for (const std::string& name : scene_names()) {
    const std::vector<cv::Mat> images = scene_images(name, 40, 30, 4);
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r, 0, false, 8, kLinear);
      test::expect_schedules_identical(encode_sequence(images, link), fixed_config(link), name + " linear r=" + r_text(r));
    }
  }
}

TEST(FixedLinearSpace, StreamingMatchesFrameOnLcdOddSizesAndStereo) {
  for (const std::string& name : {std::string("discs"), std::string("checker"), std::string("flash")}) {
    for (double r : {1.0, 0.5, 0.4}) {
      const EncoderConfig link = link_config(r, 0, true, 8, kLinear);
      test::expect_schedules_identical(encode_sequence(scene_images(name, 40, 30, 4), link), fixed_config(link, "lcd"),
                                       name + " linear lcd stereo r=" + r_text(r));
    }
  }
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(1, 1)}) {
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      for (const char* panel : {"vive", "lcd"}) {
        const EncoderConfig link = link_config(r, 0, true, 8, kLinear);
        test::expect_schedules_identical(encode_sequence(noise_images(size.width, size.height, 4, 9), link),
                                         fixed_config(link, panel),
                                         std::to_string(size.width) + "x" + std::to_string(size.height) + " linear " +
                                             panel + " r=" + r_text(r));
      }
    }
  }
}

// d_t = Q_b(enc(D(lin(E_t)))) as the encoder computes it, code for code, on every scene and noise, for both transfers
// and both link depths, except where the encoder's D lies closer to a code threshold than the decoder's D can resolve.
// The decoder computes D on the uQ1.P grid (P = 32): lin(E) from a ROM, the horizontal and the vertical sums each
// rounded to the grid, every one of the three within half an LSB, so a value within 1.5 LSB of a threshold T_k =
// lin((k - 1/2) / (2^b - 1)) may land on either side of it. That is no exact tie (the encoder's tie tolerance is 1e-9
// code) and both codes are within half a code and that distance of the exact value. Measured: one such code in this
// whole sweep, headturn (48x32, r = 1/4, sRGB 8 bits, t = 2, reduced sample (8, 4), green): the
// encoder's D = 0.026777882675417204 (45.500000045 codes, 4.9e-11 = 0.21 LSB above T_46 = 0.026777882626779784), the
// decoder's D 0.35 LSB below it, so 45 against the encoder's 46. At P = 34 (T = 28) it agrees: the grid, not the taps.
TEST(FixedLinearSpace, ReducedFrameIsTheEncodersCodeForCodeExceptWithinTheGridOfAThreshold) {
  std::vector<std::pair<std::string, std::vector<cv::Mat>>> sets;
  for (const std::string& name : scene_names()) sets.emplace_back(name, scene_images(name, 48, 32, 3));
  sets.emplace_back("noise", noise_images(48, 32, 3, 17));
  int near_threshold = 0;
  for (const auto& [name, images] : sets) {
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      for (const int bits : {8, 10}) {
        EncoderConfig link = link_config(r, 0, false, bits, kLinear);
        link.transfer = bits == 8 ? Transfer::Srgb : Transfer::Gamma22;
        const FixedDecoderConfig config = fixed_config(link, "vive", bits);
        const double grid_lsb = std::ldexp(1.0, -config.linear_resample_frac_bits);
        const double top = std::ldexp(1.0, bits) - 1.0;
        FixedFrameDecoder decoder(config);
        for (const LinkFrame& frame : encode_sequence(images, link)) {
          if (frame.meta.parity != Parity::Full) continue;
          FixedStageTaps taps;
          decoder.decode(frame, taps);
          const cv::Mat encoder_codes = reduce_codes(frame.codes, link);
          const cv::Mat expected = encoder_codes.reshape(1);
          // The encoder's D before its quantiser, in linear light.
          const cv::Mat d_linear = downsample(to_linear(dequantise(frame.codes, bits), link.transfer),
                                              encoder_codes.cols, encoder_codes.rows, link.effective_sigma())
                                       .reshape(1);
          const std::vector<std::int64_t>& d = taps[Stage::Reduced].values;
          ASSERT_EQ(d.size(), expected.total());
          for (int y = 0; y < expected.rows; ++y) {
            for (int k = 0; k < expected.cols; ++k) {
              const std::int64_t got = d[static_cast<std::size_t>(y) * static_cast<std::size_t>(expected.cols) +
                                         static_cast<std::size_t>(k)];
              const int want = expected.at<std::uint16_t>(y, k);
              if (got == want) continue;
              ++near_threshold;
              const std::string where = name + " r=" + r_text(r) + " bits=" + std::to_string(bits) +
                                        " t=" + std::to_string(frame.meta.index) + " at (" + std::to_string(k) +
                                        ", " + std::to_string(y) + ")";
              EXPECT_EQ(std::abs(got - want), 1) << where;
              const double threshold = to_linear((std::max<double>(got, want) - 0.5) / top, link.transfer);
              EXPECT_LT(std::abs(d_linear.at<double>(y, k) - threshold), 1.5 * grid_lsb) << where;
            }
          }
        }
      }
    }
  }
  EXPECT_LE(near_threshold, 1);
}

// So the reduced frame that follows a static full frame is seen as static (w = 1 everywhere).
TEST(FixedLinearSpace, ReducedFrameOfStaticContentIsSeenAsStatic) {
  for (const std::string& name : {std::string("static"), std::string("checker"), std::string("text")}) {
    for (double r : {0.5, 0.4}) {
      for (const Transfer transfer : {Transfer::Srgb, Transfer::Gamma22}) {
        EncoderConfig link = link_config(r, 0, false, 8, kLinear);
        link.transfer = transfer;
        const cv::Mat image = scene_images(name, 48, 32, 1)[0];
        const std::vector<LinkFrame> frames = encode_sequence({image, image}, link);
        FixedStreamingDecoder decoder(fixed_config(link));
        decoder.decode(frames[0]);
        const DecodedFrame reduced = decoder.decode(frames[1]);
        EXPECT_TRUE(reduced.stats.residual_applied);
        EXPECT_EQ(reduced.stats.mean_motion_weight, 1.0) << name << " r=" << r << " " << to_string(transfer);
      }
    }
  }
}

TEST(FixedLinearSpace, AgreesWithReferenceOnEveryScene) {
  for (const std::string& name : scene_names()) {
    const std::vector<cv::Mat> images = scene_images(name, 64, 48, 6);
    for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
      const EncoderConfig link = link_config(r, 0, false, 8, kLinear);
      test::expect_agreement(test::compare_with_reference(encode_sequence(images, link), fixed_config(link)),
                             name + " linear r=" + r_text(r));
    }
  }
}

TEST(FixedLinearSpace, AgreesWithReferenceOnNoise) {
  for (double r : {1.0, 0.75, 0.5, 0.4, 0.25}) {
    const EncoderConfig link = link_config(r, 0, false, 8, kLinear);
    test::expect_agreement(
        test::compare_with_reference(encode_sequence(noise_images(64, 48, 6, 100), link), fixed_config(link)),
        "noise linear r=" + r_text(r));
  }
  EncoderConfig gamma10 = link_config(0.5, 0, false, 10, kLinear);
  gamma10.transfer = Transfer::Gamma22;
  test::expect_agreement(test::compare_with_reference(encode_sequence(noise_images(64, 48, 6, 300), gamma10),
                                                      fixed_config(gamma10, "vive", 10)),
                         "noise linear 10-bit gamma2.2");
  const EncoderConfig stereo = link_config(0.5, 1, true, 8, kLinear);
  test::expect_agreement(test::compare_with_reference(encode_sequence(noise_images(61, 37, 6, 200), stereo),
                                                      fixed_config(stereo)),
                         "noise linear stereo 61x37");
}

TEST(FixedLinearSpace, AgreesWithReferenceOnLcd) {
  for (const std::string& name : {std::string("discs"), std::string("panorama")}) {
    const EncoderConfig link = link_config(0.5, 0, false, 8, kLinear);
    test::expect_lcd_agreement(test::compare_with_reference(encode_sequence(scene_images(name, 48, 32, 6), link),
                                                            fixed_config(link, "lcd")),
                               name + " linear lcd");
  }
}

TEST(FixedLinearSpace, ReportsLinearLineBufferAndReEncodingRom) {
  const FixedStreamingDecoder decoder(fixed_config(link_config(0.5, 0, false, 8, kLinear)));
  const FixedStreamingReport r = decoder.report(cv::Size(1080, 1200));
  const FixedDecoderConfig defaults;
  EXPECT_EQ(r.buffers[0].bits, 1 + defaults.linear_resample_frac_bits);
  const auto d_store = std::find_if(r.buffers.begin(), r.buffers.end(), [](const FixedBufferReport& b) {
    return b.name.rfind("frame: d_t", 0) == 0;
  });
  ASSERT_NE(d_store, r.buffers.end());
  EXPECT_EQ(d_store->bits, 8);  // link codes
  const auto has_rom = [&](const std::string& prefix) {
    return std::any_of(r.roms.begin(), r.roms.end(),
                       [&](const FixedRomReport& rom) { return rom.name.rfind(prefix, 0) == 0; });
  };
  EXPECT_TRUE(has_rom("D re-encoding"));
  EXPECT_TRUE(has_rom("D input lin(E)"));
  EXPECT_FALSE(has_rom("L, alpha = lin(U(.))"));  // no EOTF LUT: U outputs linear light
}

}  // namespace
}  // namespace trm
