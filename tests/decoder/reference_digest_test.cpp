// The double reference decoder is the oracle every agreement test and sweep compares against, so its outputs must not
// move unnoticed: a digest of every output plane, stage plane and statistic of a short sequence, per panel and
// configuration, against the digests recorded when they were last meant to change. A change that is meant to move
// the reference (new math, a fixed bug) updates them and says why in its commit; a speed-up never does.
//
// The inputs are made without libm (cv::RNG, integer shifts), so the digests depend only on IEEE arithmetic and the C
// library's pow and exp, whose FMA builds glibc selects on this project's machines; a CPU without FMA takes glibc's
// other builds, whose last bits may differ, and skips the test.
#include "decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace trm {
namespace {

class Digest {
 public:
  void add(const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) {
      value_ ^= b[i];
      value_ *= 1099511628211ULL;  // FNV-1a, 64 bits
    }
  }
  void add(double v) { add(&v, sizeof v); }
  void add(const cv::Mat& m) {
    const int shape[3] = {m.rows, m.cols, m.type()};
    add(shape, sizeof shape);
    for (int y = 0; y < m.rows; ++y) add(m.ptr(y), m.cols * m.elemSize());
  }
  std::uint64_t value() const { return value_; }

 private:
  std::uint64_t value_ = 14695981039346656037ULL;
};

cv::Mat frame_at(std::int64_t t) { return test::half_moving_frame(160, 48, 20261206, t); }

struct Case {
  const char* name;
  const char* panel;
  bool variant;  // gamma 2.2, 10-bit link and output, r = 1/4, contributed LCD history, s = 3
  std::uint64_t digest;
};

std::uint64_t digest_of(const Case& c) {
  EncoderConfig link;
  if (c.variant) {
    link.transfer = Transfer::Gamma22;
    link.bits = 10;
    link.reduction = 0.25;
  }
  DecoderConfig config = test::decoder_config(link, c.panel);
  if (c.variant) {
    config.output_bits = 10;
    config.lcd_history = LcdHistory::Contributed;
    config.sensitivity = 3.0;
  }
  ReferenceDecoder decoder(config);
  const TrmEncoder encoder(link);
  Digest digest;
  for (std::int64_t t = 0; t < 6; ++t) {
    const DecodedFrame d = decoder.decode(encoder.encode(frame_at(t), t));
    for (const cv::Mat* m : {&d.wanted_linear, &d.drive, &d.drive_codes, &d.emitted_linear}) digest.add(*m);
    for (const double v : {d.stats.clipped_fraction, d.stats.residual_mean_abs, d.stats.residual_max_abs,
                           d.stats.dropped_sum, d.stats.mean_motion_weight, d.stats.lcd_unreachable_fraction}) {
      digest.add(v);
    }
    if (d.stages) {
      for (const cv::Mat& m : d.stages->planes) digest.add(m);
    }
  }
  return digest.value();
}

TEST(ReferenceDigest, OutputsAreTheRecordedOnes) {
  if (!__builtin_cpu_supports("fma")) GTEST_SKIP() << "no FMA: glibc's pow and exp take builds of other last bits";
  const Case cases[] = {
      {"vive", "vive", false, 0xd589ad641755c33f},
      {"vive, variant", "vive", true, 0xa29331f4bb74f9b2},
      {"lcd", "lcd", false, 0x2a755d34c3a0334c},
      {"lcd, variant", "lcd", true, 0xf89ffee52b55b66b},
      {"lcd unusual merge", "lcd:0.3,-0.2,0.45,0.02,2.4", false, 0x98403ad2561354e3},
      {"gamma 1.8, variant", "gamma:1.8", true, 0x1b7054abdd88e9f7},
  };
  for (const Case& c : cases) {
    char actual[32];
    std::snprintf(actual, sizeof actual, "0x%016llx", static_cast<unsigned long long>(digest_of(c)));
    char recorded[32];
    std::snprintf(recorded, sizeof recorded, "0x%016llx", static_cast<unsigned long long>(c.digest));
    EXPECT_STREQ(actual, recorded) << c.name << ": the reference decoder's outputs changed";
  }
}

}  // namespace
}  // namespace trm
