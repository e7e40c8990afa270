// Metrics against answers worked out by hand: the Talbot-Plateau mean, PSNR of a known error, the full-rate
// emission of values on and between drive codes, code agreement of constructed images and the DESIGN §6 criterion
// at its boundary.
#include "trm/metrics.hpp"

#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

// 1000 codes (20 x 50, one channel) of value 500, of which the first `differing` are `by` LSB higher.
cv::Mat codes_differing(int differing, int by) {
  cv::Mat codes(20, 50, CV_16UC1, cv::Scalar(500));
  for (int k = 0; k < differing; ++k) codes.at<std::uint16_t>(k / 50, k % 50) = static_cast<std::uint16_t>(500 + by);
  return codes;
}

const cv::Mat kReference = codes_differing(0, 0);

TEST(PerceivedPair, IsTheTimeAverage) {
  cv::Mat a(2, 3, CV_64FC3, cv::Scalar(0.2, 0.4, 1.0));
  cv::Mat b(2, 3, CV_64FC3, cv::Scalar(0.6, 0.0, 1.0));
  const cv::Mat p = perceived_pair(a, b);
  ASSERT_EQ(p.type(), CV_64FC3);
  EXPECT_EQ(p.at<cv::Vec3d>(1, 2), cv::Vec3d(0.4, 0.2, 1.0));
  EXPECT_THROW(perceived_pair(a, cv::Mat(2, 2, CV_64FC3)), std::invalid_argument);
  EXPECT_THROW(perceived_pair(a, cv::Mat(2, 3, CV_32FC3)), std::invalid_argument);
}

TEST(PerceivedPair, OnAnLcdIsTheMergedEmission) {
  const cv::Mat previous(1, 2, CV_64FC3, cv::Scalar::all(0.1));
  const cv::Mat current(1, 2, CV_64FC3, cv::Scalar::all(0.3));
  const cv::Mat oled = perceived_pair(parse_panel("vive"), previous, current);
  EXPECT_EQ(oled.at<cv::Vec3d>(0, 1), cv::Vec3d::all(0.2));
  const cv::Mat lcd = perceived_pair(parse_panel("lcd"), previous, current);
  EXPECT_EQ(lcd.at<cv::Vec3d>(0, 1), cv::Vec3d::all(0.3));
  EXPECT_NE(lcd.data, current.data);  // a copy: the caller keeps its frame
}

TEST(Psnr, OfAConstantErrorOnTheEncoding) {
  // Every sample 0.1 apart in sRGB: MSE 0.01, PSNR 20 dB.
  const cv::Mat a = to_linear(cv::Mat(4, 5, CV_64FC3, cv::Scalar::all(0.5)), Transfer::Srgb);
  const cv::Mat b = to_linear(cv::Mat(4, 5, CV_64FC3, cv::Scalar::all(0.6)), Transfer::Srgb);
  EXPECT_NEAR(psnr_srgb(a, b), 20.0, 1e-9);
  EXPECT_NEAR(psnr_srgb(b, a), 20.0, 1e-9);
}

TEST(Psnr, OfOneFullScaleSample) {
  // Black against black with one sample at white (0 and 1 in both encodings): MSE 1/60.
  const cv::Mat a(4, 5, CV_64FC3, cv::Scalar::all(0.0));
  cv::Mat b = a.clone();
  b.at<cv::Vec3d>(2, 3)[1] = 1.0;
  EXPECT_NEAR(psnr_srgb(a, b), 10.0 * std::log10(60.0), 1e-12);
  EXPECT_EQ(psnr_srgb(a, a.clone()), std::numeric_limits<double>::infinity());
}

TEST(FullRateEmission, IsTheLightOfTheNearestDriveCode) {
  const Panel panel = parse_panel("generic");  // OLED, gamma 2.2 on every channel
  cv::Mat linear(1, 3, CV_64FC3);
  linear.at<cv::Vec3d>(0, 0) = cv::Vec3d::all(std::pow(100.0 / 255.0, 2.2));  // on code 100
  linear.at<cv::Vec3d>(0, 1) = cv::Vec3d::all(std::pow(100.4 / 255.0, 2.2));  // rounds down to 100
  linear.at<cv::Vec3d>(0, 2) = cv::Vec3d::all(std::pow(100.6 / 255.0, 2.2));  // rounds up to 101
  const cv::Mat emitted = full_rate_emission(linear, panel, 8);
  ASSERT_EQ(emitted.type(), CV_64FC3);
  const double on_100 = std::pow(100.0 / 255.0, 2.2), on_101 = std::pow(101.0 / 255.0, 2.2);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(emitted.at<cv::Vec3d>(0, 0)[c], on_100, 1e-15);
    EXPECT_NEAR(emitted.at<cv::Vec3d>(0, 1)[c], on_100, 1e-15);
    EXPECT_NEAR(emitted.at<cv::Vec3d>(0, 2)[c], on_101, 1e-15);
  }
}

// The tables' form against the per-sample one, bit for bit, OLED and LCD panels at 8 and 10 bits: a row of values
// near every code's crossing (within and just past OledDriveCodes' guard of 256 ulps, where its lookup and its pow
// meet) and random ones, which an OLED takes through its tables; and a row with NaN, infinities and values outside
// [0, 1], which an OLED takes per sample (a NaN anywhere in a row does).
TEST(FullRateEmission, TheTablesGiveThePerSampleDoubles) {
  const auto ulps_away = [](double x, std::int64_t n) {
    return std::bit_cast<double>(static_cast<std::int64_t>(std::bit_cast<std::uint64_t>(x)) + n);
  };
  for (const std::string spec : {"vive", "rift", "gamma:0.5,2.2,4", "lcd", "lcd:0.3,0.1,0.3,0,2.4"}) {
    const Panel panel = parse_panel(spec);
    for (const int bits : {8, 10}) {
      const int top = (1 << bits) - 1;
      std::vector<double> near_crossings;
      for (int c = 0; c < 3; ++c) {
        for (int k = 1; k <= top; ++k) {
          // The linear value whose drive is half a code below k: where code k begins, give or take the pow's error.
          const double crossing = panel.linear_from_drive((k - 0.5) / top, c);
          for (const std::int64_t n : {-300, -257, -256, -255, -2, -1, 0, 1, 2, 255, 256, 257, 300}) {
            while (near_crossings.size() % 3 != static_cast<std::size_t>(c)) near_crossings.push_back(0.5);
            near_crossings.push_back(ulps_away(crossing, n));
          }
        }
      }
      std::mt19937_64 random(7);
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      for (int i = 0; i < 3000; ++i) near_crossings.push_back(unit(random));
      for (const double x : {0.0, -0.0, 1.0, 5e-324}) near_crossings.push_back(x);
      std::vector<double> edges = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity(), -1e-300, 1.5, -2.0, 0.5, 0.25, 1e-3};
      const FullRateEmission tables(panel, bits);
      for (std::vector<double>* values : {&near_crossings, &edges}) {
        while (values->size() % 3 != 0) values->push_back(0.25);
        const cv::Mat linear = cv::Mat(*values, true).reshape(3, 1);
        const cv::Mat expected = full_rate_emission(linear, panel, bits);
        const cv::Mat got = tables(linear);
        ASSERT_EQ(got.type(), CV_64FC3);
        ASSERT_EQ(got.size(), expected.size());
        const double* a = expected.ptr<double>(0);
        const double* b = got.ptr<double>(0);
        for (std::size_t k = 0; k < values->size(); ++k) {
          ASSERT_TRUE(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k])))
              << spec << " " << bits << "-bit sample " << k << " x = " << (*values)[k] << ": " << a[k] << " against "
              << b[k];
        }
      }
    }
  }
  EXPECT_THROW(FullRateEmission(parse_panel("vive"), 0), std::invalid_argument);
  EXPECT_THROW(FullRateEmission(parse_panel("lcd"), 17), std::invalid_argument);
}

TEST(CodeAgreement, CountsIdenticalCodesOfEveryChannel) {
  // 2 x 2 pixels x 3 channels = 12 codes; 3 of them differ, by 1, 2 and 1 LSB.
  cv::Mat reference(2, 2, CV_16UC3, cv::Scalar(10, 20, 30));
  cv::Mat codes = reference.clone();
  codes.at<cv::Vec3w>(0, 1)[2] = 31;
  codes.at<cv::Vec3w>(1, 0)[0] = 8;
  codes.at<cv::Vec3w>(1, 1)[1] = 21;
  const CodeAgreement a = compare_codes(codes, reference);
  EXPECT_EQ(a.compared, 12);
  EXPECT_EQ(a.identical, 9);
  EXPECT_EQ(a.differing(), 3);
  EXPECT_DOUBLE_EQ(a.identical_fraction(), 0.75);
  EXPECT_DOUBLE_EQ(a.identical_percent(), 75.0);
  EXPECT_EQ(a.max_lsb, 2.0);
  EXPECT_DOUBLE_EQ(a.mean_lsb(), 4.0 / 12.0);
  EXPECT_DOUBLE_EQ(a.rms_lsb(), std::sqrt(6.0 / 12.0));
}

TEST(CodeAgreement, AccumulatesViews) {
  CodeAgreement total;
  total += compare_codes(codes_differing(3, 1), kReference);
  total += compare_codes(codes_differing(1, 5), kReference);
  total += compare_codes(kReference, kReference);
  EXPECT_EQ(total.compared, 3000);
  EXPECT_EQ(total.identical, 2996);
  EXPECT_EQ(total.max_lsb, 5.0);
  EXPECT_DOUBLE_EQ(total.sum_lsb, 8.0);
  EXPECT_DOUBLE_EQ(total.sum_squared_lsb, 28.0);
}

TEST(CodeAgreement, RejectsImagesThatDoNotMatch) {
  EXPECT_THROW(compare_codes(kReference, cv::Mat(20, 49, CV_16UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(compare_codes(kReference, cv::Mat(20, 50, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(compare_codes(cv::Mat(2, 2, CV_64FC1), cv::Mat(2, 2, CV_64FC1)), std::invalid_argument);
  EXPECT_EQ(compare_codes(cv::Mat(), cv::Mat()).compared, 0);
}

TEST(MergeDifference, IsInOutputCodes) {
  // LCD (gamma 2.2): merges 0.5 and 0.5 + 3/255 emit M^2.2; recovered, they are 3 codes apart at 8 bits.
  const LcdPanel lcd = parse_panel("lcd").lcd;
  const cv::Mat a(2, 2, CV_64FC3, cv::Scalar::all(std::pow(0.5, 2.2)));
  cv::Mat b = a.clone();
  b.at<cv::Vec3d>(1, 0)[2] = std::pow(0.5 + 3.0 / 255.0, 2.2);
  EXPECT_NEAR(max_merge_difference_codes(a, b, lcd, 8), 3.0, 1e-9);
  EXPECT_EQ(max_merge_difference_codes(a, a.clone(), lcd, 8), 0.0);
}

TEST(ReferenceAgreementCriterion, IsDesignSection6) {
  EXPECT_EQ(kReferenceAgreementCriterion.min_identical_fraction, 0.999);
  EXPECT_EQ(kReferenceAgreementCriterion.min_identical_percent(), 99.9);
  EXPECT_EQ(kReferenceAgreementCriterion.max_lsb, 1.0);
}

TEST(ReferenceAgreementCriterion, ExactlyTheBoundaryPasses) {
  // 999 of 1000 codes identical is exactly 99.9 %; the one differing by 1 LSB is allowed.
  const CodeAgreement a = compare_codes(codes_differing(1, 1), kReference);
  EXPECT_EQ(a.identical, 999);
  EXPECT_TRUE(kReferenceAgreementCriterion.met_by(a));
  // The same share over many views.
  CodeAgreement many;
  for (int view = 0; view < 7; ++view) many += a;
  EXPECT_TRUE(kReferenceAgreementCriterion.met_by(many));
  EXPECT_TRUE(kReferenceAgreementCriterion.met_by(compare_codes(kReference, kReference)));
}

TEST(ReferenceAgreementCriterion, JustBelowTheBoundaryFails) {
  // 998 of 1000, and 9989 of 10000 (99.89 %).
  EXPECT_FALSE(kReferenceAgreementCriterion.met_by(compare_codes(codes_differing(2, 1), kReference)));
  CodeAgreement views;
  for (int view = 0; view < 9; ++view) views += compare_codes(codes_differing(1, 1), kReference);
  views += compare_codes(codes_differing(2, 1), kReference);
  EXPECT_EQ(views.identical, 9989);
  EXPECT_FALSE(kReferenceAgreementCriterion.met_by(views));
  EXPECT_TRUE(kReferenceAgreementCriterion.met_by(9990, 10000, 1.0));
  EXPECT_FALSE(kReferenceAgreementCriterion.met_by(9989, 10000, 1.0));
}

TEST(ReferenceAgreementCriterion, TwoLsbFails) {
  // One code of 1000 two LSB away: the share passes, the distance does not.
  const CodeAgreement a = compare_codes(codes_differing(1, 2), kReference);
  EXPECT_EQ(a.identical, 999);
  EXPECT_EQ(a.max_lsb, 2.0);
  EXPECT_FALSE(kReferenceAgreementCriterion.met_by(a));
}

TEST(ReferenceAgreementCriterion, NothingComparedFails) {
  EXPECT_FALSE(kReferenceAgreementCriterion.met_by(CodeAgreement{}));
}

// SSIM against Wang et al.'s formula on constant images, where the local statistics are exact: two constants mu_a,
// mu_b give (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1), C1 = (0.01 * 255)^2.
TEST(Ssim, MatchesTheDefinitionOnConstantImagesAndIsOneForIdenticalOnes) {
  const double mu_a = 100.0, mu_b = 110.0;
  const auto linear_of = [](double display) { return to_linear(display / 255.0, Transfer::Srgb); };
  const cv::Mat a(24, 24, CV_64FC3, cv::Scalar::all(linear_of(mu_a)));
  const cv::Mat b(24, 24, CV_64FC3, cv::Scalar::all(linear_of(mu_b)));
  const double c1 = (0.01 * 255.0) * (0.01 * 255.0);
  EXPECT_NEAR(ssim_srgb(a, b), (2 * mu_a * mu_b + c1) / (mu_a * mu_a + mu_b * mu_b + c1), 1e-9);
  cv::Mat noise(24, 24, CV_64FC3);
  cv::randu(noise, cv::Scalar::all(0.0), cv::Scalar::all(1.0));
  EXPECT_NEAR(ssim_srgb(noise, noise), 1.0, 1e-12);
  cv::Mat blurred;
  cv::blur(noise, blurred, cv::Size(3, 3));
  EXPECT_LT(ssim_srgb(noise, blurred), 0.9);
  EXPECT_NEAR(ssim_srgb(noise, blurred), ssim_srgb(blurred, noise), 1e-12);
  EXPECT_THROW(ssim_srgb(a, cv::Mat(24, 23, CV_64FC3, cv::Scalar::all(0.5))), std::invalid_argument);
}

}  // namespace
}  // namespace trm
