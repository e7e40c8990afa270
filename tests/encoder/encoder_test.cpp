// The TRM encoder: parity, reduced frame = Q_b(D(E_q)) of the quantised full frame, metadata.
#include "trm/encoder.hpp"
#include "trm/encoder_json.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace trm {
namespace {

cv::Mat random_linear(int w, int h, std::uint64_t seed) {
  cv::Mat m(h, w, CV_64FC3);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0.0, 1.0);
  return m;
}

TEST(EncoderConfig, ValidatesEveryField) {
  EncoderConfig ok;
  EXPECT_NO_THROW(ok.validate());
  EXPECT_DOUBLE_EQ(ok.effective_sigma(), 2.5);
  auto bad = [](auto mutate) {
    EncoderConfig c;
    mutate(c);
    return c;
  };
  EXPECT_THROW(bad([](EncoderConfig& c) { c.reduction = 0.0; }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.reduction = 1.01; }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.reduction = std::nan(""); }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.sigma = -1.0; }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.sigma = INFINITY; }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.bits = 12; }).validate(), std::invalid_argument);
  EXPECT_THROW(bad([](EncoderConfig& c) { c.phase = 2; }).validate(), std::invalid_argument);
  EncoderConfig given;
  given.sigma = 1.7;
  EXPECT_DOUBLE_EQ(given.effective_sigma(), 1.7);
  given.sigma = 0.0;
  given.reduction = 0.25;
  EXPECT_DOUBLE_EQ(given.effective_sigma(), 5.0);
}

TEST(Parity, MonoPhaseAndStereo) {
  EncoderConfig c;
  for (std::int64_t t = 0; t < 6; ++t) EXPECT_EQ(parity_of(t, 0, c), t % 2 == 0 ? Parity::Full : Parity::Reduced);
  c.phase = 1;
  for (std::int64_t t = 0; t < 6; ++t) EXPECT_EQ(parity_of(t, 0, c), t % 2 == 0 ? Parity::Reduced : Parity::Full);
  for (int phase : {0, 1}) {
    c.phase = phase;
    c.stereo = true;
    for (std::int64_t t = 0; t < 6; ++t) {
      EXPECT_NE(parity_of(t, 0, c), parity_of(t, 1, c)) << "every link frame carries one full and one reduced view";
      EXPECT_NE(parity_of(t, 1, c), parity_of(t + 1, 1, c));
    }
  }
  EXPECT_THROW(parity_of(-1, 0, c), std::invalid_argument);
  EXPECT_THROW(parity_of(0, 2, c), std::invalid_argument);
}

TEST(TrmEncoder, FullFrameIsTheQuantisedEncodedFrame) {
  const cv::Mat img = random_linear(31, 17, 4);
  for (Transfer tf : {Transfer::Srgb, Transfer::Gamma22}) {
    for (int bits : {8, 10}) {
      EncoderConfig c;
      c.transfer = tf;
      c.bits = bits;
      const LinkFrame f = TrmEncoder(c).encode(img, 4);
      EXPECT_EQ(f.meta.parity, Parity::Full);
      ASSERT_EQ(f.codes.type(), CV_16UC3);
      // Independent per-pixel check against the scalar transfer function.
      const double max_code = (1 << bits) - 1;
      for (int y = 0; y < img.rows; ++y)
        for (int x = 0; x < img.cols; ++x)
          for (int ch = 0; ch < 3; ++ch) {
            const double e = to_encoded(img.at<cv::Vec3d>(y, x)[ch], tf);
            EXPECT_EQ((f.codes.at<cv::Vec<std::uint16_t, 3>>(y, x)[ch]), std::floor(e * max_code + 0.5));
          }
      EXPECT_EQ(f.meta.width, 31);
      EXPECT_EQ(f.meta.full_width, 31);
      EXPECT_EQ(f.meta.bits, bits);
      EXPECT_EQ(f.meta.transfer, tf);
    }
  }
}

TEST(TrmEncoder, ReducedFrameIsQofDofTheQuantisedFullFrame) {
  const cv::Mat img = random_linear(97, 61, 9);
  for (ResampleSpace space : {ResampleSpace::Encoded, ResampleSpace::Linear}) {
    EncoderConfig c;
    c.resample_space = space;
    const LinkFrame full = TrmEncoder(c).encode(img, 2);
    const LinkFrame reduced = TrmEncoder(c).encode(img, 3);
    EXPECT_EQ(reduced.meta.parity, Parity::Reduced);
    EXPECT_EQ(reduced.meta.width, 49);
    EXPECT_EQ(reduced.meta.height, 31);
    EXPECT_EQ(reduced.meta.full_width, 97);
    EXPECT_EQ(reduced.meta.full_height, 61);
    EXPECT_EQ(reduced.meta.index, 3);
    const cv::Mat e = dequantise(full.codes, 8);
    cv::Mat expected;
    if (space == ResampleSpace::Encoded) {
      expected = quantise_reduced(downsample(e, 49, 31, 2.5), 8);
    } else {
      expected = quantise_reduced(to_encoded(downsample(to_linear(e, Transfer::Srgb), 49, 31, 2.5), Transfer::Srgb), 8);
    }
    EXPECT_EQ(cv::norm(reduced.codes, expected, cv::NORM_INF), 0.0) << to_string(space);
    EXPECT_EQ(cv::norm(reduce_codes(full.codes, c), expected, cv::NORM_INF), 0.0);
  }
}

TEST(TrmEncoder, LinearAndEncodedResamplingDiffer) {
  cv::Mat edge(16, 16, CV_64FC3, cv::Scalar::all(0.0));
  edge.colRange(8, 16).setTo(cv::Scalar::all(1.0));
  EncoderConfig enc, lin;
  lin.resample_space = ResampleSpace::Linear;
  const LinkFrame a = TrmEncoder(enc).encode(edge, 1);
  const LinkFrame b = TrmEncoder(lin).encode(edge, 1);
  EXPECT_GT(cv::norm(a.codes, b.codes, cv::NORM_INF), 0.0);
}

TEST(TrmEncoder, StaticContentGivesIdenticalReducedFrames) {
  const cv::Mat img = random_linear(40, 30, 12);
  const TrmEncoder encoder{EncoderConfig{}};
  const LinkFrame first = encoder.encode(img, 1);
  for (std::int64_t t : {3, 5, 101}) {
    const LinkFrame later = encoder.encode(img, t);
    EXPECT_EQ(cv::norm(first.codes, later.codes, cv::NORM_INF), 0.0);
  }
}

TEST(TrmEncoder, StereoPairCarriesOneFullAndOneReducedView) {
  EncoderConfig c;
  c.stereo = true;
  const TrmEncoder encoder(c);
  const cv::Mat img = random_linear(20, 12, 1);
  for (std::int64_t t = 0; t < 4; ++t) {
    const LinkFrame left = encoder.encode(img, t, 0);
    const LinkFrame right = encoder.encode(img, t, 1);
    EXPECT_NE(left.meta.parity, right.meta.parity);
    EXPECT_EQ(right.meta.eye, 1);
    // Pixel count per link frame is constant in stereo: W*H + w*h.
    EXPECT_EQ(left.codes.total() + right.codes.total(), 20u * 12u + 10u * 6u);
  }
}

TEST(TrmEncoder, TinySizesAndRatesWork) {
  EncoderConfig c;
  c.reduction = 0.05;
  const TrmEncoder encoder(c);
  const cv::Mat one = random_linear(1, 1, 3);
  const LinkFrame r = encoder.encode(one, 1);
  EXPECT_EQ(r.codes.size(), cv::Size(1, 1));
  // A 1x1 image blurred with replicate borders is itself.
  EXPECT_EQ(cv::norm(r.codes, encoder.encode(one, 0).codes, cv::NORM_INF), 0.0);
  c.reduction = 1.0;
  const LinkFrame same = TrmEncoder(c).encode(random_linear(7, 5, 2), 1);
  EXPECT_EQ(same.codes.size(), cv::Size(7, 5));
}

TEST(TrmEncoder, RejectsInvalidFrames) {
  const TrmEncoder encoder{EncoderConfig{}};
  cv::Mat img = random_linear(8, 8, 1);
  img.at<cv::Vec3d>(3, 3)[1] = std::nan("");
  EXPECT_THROW(encoder.encode(img, 0), std::invalid_argument);
  img.at<cv::Vec3d>(3, 3)[1] = -0.5;
  EXPECT_THROW(encoder.encode(img, 0), std::invalid_argument);
  img.at<cv::Vec3d>(3, 3)[1] = INFINITY;
  EXPECT_THROW(encoder.encode(img, 0), std::invalid_argument);
  EXPECT_THROW(encoder.encode(cv::Mat::zeros(4, 4, CV_64FC1), 0), std::invalid_argument);
  EncoderConfig bad;
  bad.bits = 9;
  EXPECT_THROW(TrmEncoder{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace trm

// highest_code against cv::minMaxLoc (the check it replaces): random codes of every width, 1 and 3 channels, the
// largest code anywhere in a row (first, last, a row's middle), a region of a larger image (rows not contiguous, the
// region's neighbours higher than anything inside it), empty; another depth is refused.
TEST(HighestCode, AgreesWithMinMaxLocAndReadsOnlyTheImage) {
  cv::RNG random(11);
  for (const int channels : {1, 3}) {
    for (const int width : {1, 2, 7, 33, 2160}) {
      cv::Mat codes(5, width, CV_16UC(channels));
      random.fill(codes, cv::RNG::UNIFORM, 0, 1000);
      for (const int at : {0, width * channels - 1, (width * channels) / 2}) {
        cv::Mat probe = codes.clone();
        probe.ptr<std::uint16_t>(3)[at] = 1023;
        double expected = 0.0;
        cv::minMaxLoc(probe.reshape(1), nullptr, &expected);
        EXPECT_EQ(trm::highest_code(probe), static_cast<int>(expected)) << channels << " channels, width " << width;
      }
      double expected = 0.0;
      cv::minMaxLoc(codes.reshape(1), nullptr, &expected);
      EXPECT_EQ(trm::highest_code(codes), static_cast<int>(expected));
    }
  }
  cv::Mat larger(40, 50, CV_16UC3, cv::Scalar::all(900));
  cv::Mat region = larger(cv::Rect(5, 6, 20, 10));
  region.setTo(cv::Scalar::all(17));
  region.at<cv::Vec3w>(9, 19)[2] = 300;
  ASSERT_FALSE(region.isContinuous());
  EXPECT_EQ(trm::highest_code(region), 300);
  EXPECT_EQ(trm::highest_code(cv::Mat()), 0);
  EXPECT_THROW(trm::highest_code(cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(1))), std::invalid_argument);
}

// One writer and one reader of the encoder configuration (capture headers, reports).
TEST(EncoderJson, RoundTripsAndRefusesWhatTheCommandLineWouldRefuse) {
  trm::EncoderConfig config;
  config.reduction = 0.25;
  config.phase = 1;
  config.transfer = trm::Transfer::Gamma22;
  config.resample_space = trm::ResampleSpace::Linear;
  config.bits = 10;
  config.stereo = true;
  const nlohmann::ordered_json j = trm::encoder_json(config);
  EXPECT_EQ(j["sigma"].get<double>(), 5.0);  // the effective sigma, 1.25 / r
  const trm::EncoderConfig back = trm::encoder_config_from_json(j);
  EXPECT_EQ(back.reduction, config.reduction);
  EXPECT_EQ(back.effective_sigma(), config.effective_sigma());
  EXPECT_EQ(back.phase, 1);
  EXPECT_EQ(back.transfer, trm::Transfer::Gamma22);
  EXPECT_EQ(back.resample_space, trm::ResampleSpace::Linear);
  EXPECT_EQ(back.bits, 10);
  EXPECT_TRUE(back.stereo);
  EXPECT_EQ(trm::encoder_json(back), j);
  for (const char* field : {"reduction", "sigma", "phase", "transfer", "resample_space", "bits", "stereo"}) {
    nlohmann::json missing = j;
    missing.erase(field);
    try {
      (void)trm::encoder_config_from_json(missing);
      ADD_FAILURE() << "accepted a configuration without " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
  nlohmann::json bad = j;
  bad["bits"] = 9;
  EXPECT_THROW((void)trm::encoder_config_from_json(bad), std::invalid_argument);
  bad = j;
  bad["reduction"] = "half";
  EXPECT_THROW((void)trm::encoder_config_from_json(bad), std::invalid_argument);
  EXPECT_THROW((void)trm::encoder_config_from_json(nlohmann::json::array()), std::invalid_argument);
}
