// Transfer functions, quantisation and luma against hand-computed IEC 61966-2-1 / Rec. 709 values.
#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

TEST(Transfer, SrgbMatchesStandardValues) {
  // Reference values evaluated independently from the IEC 61966-2-1 formulas.
  EXPECT_NEAR(to_linear(0.02, Transfer::Srgb), 0.0015479876160990713, 1e-15);   // linear segment
  EXPECT_NEAR(to_linear(0.5, Transfer::Srgb), 0.21404114048223255, 1e-15);
  EXPECT_NEAR(to_linear(0.735, Transfer::Srgb), 0.4994581635400763, 1e-15);
  EXPECT_NEAR(to_encoded(0.001, Transfer::Srgb), 0.012920000000000001, 1e-15);
  EXPECT_NEAR(to_encoded(0.18, Transfer::Srgb), 0.46135612950044164, 1e-15);
  EXPECT_DOUBLE_EQ(to_linear(0.0, Transfer::Srgb), 0.0);
  EXPECT_DOUBLE_EQ(to_linear(1.0, Transfer::Srgb), 1.0);
  EXPECT_DOUBLE_EQ(to_encoded(1.0, Transfer::Srgb), 1.0);
}

TEST(Transfer, SrgbIsContinuousAtTheBreakPoint) {
  const double below = to_linear(0.04045, Transfer::Srgb);
  const double above = to_linear(std::nextafter(0.04045, 1.0), Transfer::Srgb);
  EXPECT_NEAR(below, above, 1e-7);
}

TEST(Transfer, Gamma22IsAPurePower) {
  EXPECT_NEAR(to_linear(0.5, Transfer::Gamma22), 0.217637640824031, 1e-15);
  EXPECT_NEAR(to_encoded(0.18, Transfer::Gamma22), 0.4586564468643811, 1e-15);
}

TEST(Transfer, RoundTripsAndClampsOutOfRangeInput) {
  for (Transfer tf : {Transfer::Srgb, Transfer::Gamma22}) {
    for (int i = 0; i <= 1000; ++i) {
      const double v = i / 1000.0;
      EXPECT_NEAR(to_encoded(to_linear(v, tf), tf), v, 1e-12) << to_string(tf) << " v=" << v;
    }
    EXPECT_EQ(to_linear(-0.3, tf), 0.0);
    EXPECT_EQ(to_linear(1.7, tf), 1.0);
    EXPECT_EQ(to_encoded(-0.3, tf), 0.0);
    EXPECT_EQ(to_encoded(1.7, tf), 1.0);
  }
}

TEST(Transfer, MatVersionsAgreeWithScalarForAnyChannelCount) {
  for (int channels : {1, 3, 4}) {
    cv::Mat m(7, 5, CV_MAKETYPE(CV_64F, channels));
    cv::randu(m, -0.1, 1.1);
    const cv::Mat lin = to_linear(m, Transfer::Srgb);
    const cv::Mat enc = to_encoded(m, Transfer::Gamma22);
    ASSERT_EQ(lin.type(), m.type());
    ASSERT_EQ(enc.size(), m.size());
    for (int y = 0; y < m.rows; ++y) {
      for (int i = 0; i < m.cols * channels; ++i) {
        const double v = m.ptr<double>(y)[i];
        EXPECT_EQ(lin.ptr<double>(y)[i], to_linear(v, Transfer::Srgb));
        EXPECT_EQ(enc.ptr<double>(y)[i], to_encoded(v, Transfer::Gamma22));
      }
    }
  }
}

// The array versions (vector pows, element-wise steps possibly in AVX2) against the scalar functions, bit for bit:
// both transfers, both directions, in place and not, values around the segment breaks, 0, 1, out of range and NaN,
// and lengths across the chunk size with tails.
TEST(Transfer, ArrayVersionsAreTheScalarFunctionsBitForBit) {
  const auto bits = [](double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  };
  std::vector<double> values;
  for (int k = 0; k < 700; ++k) values.push_back(-0.05 + 1.1 * std::fmod(k * 0.6180339887498949, 1.0));
  for (const double v : {0.0, -0.0, 1.0, 0.04045, 0.0031308, std::nextafter(0.04045, 1.0),
                         std::nextafter(0.0031308, 0.0), 1e-300, std::nan(""), -1.0, 2.0}) {
    values.push_back(v);
  }
  for (const std::size_t n : {std::size_t{1}, std::size_t{255}, std::size_t{257}, values.size()}) {
    const std::span<const double> in(values.data(), n);
    for (const Transfer transfer : {Transfer::Srgb, Transfer::Gamma22}) {
      std::vector<double> linear(n);
      std::vector<double> encoded(n);
      to_linear(in, linear, transfer);
      to_encoded(in, encoded, transfer);
      std::vector<double> in_place(in.begin(), in.end());
      to_linear(in_place, in_place, transfer);
      for (std::size_t k = 0; k < n; ++k) {
        ASSERT_EQ(bits(linear[k]), bits(to_linear(in[k], transfer))) << "n " << n << " k " << k << " " << in[k];
        ASSERT_EQ(bits(encoded[k]), bits(to_encoded(in[k], transfer))) << "n " << n << " k " << k << " " << in[k];
        ASSERT_EQ(bits(in_place[k]), bits(linear[k])) << "n " << n << " k " << k;
      }
    }
  }
  std::vector<double> shorter(2);
  EXPECT_THROW(to_linear(std::vector<double>(3), shorter, Transfer::Srgb), std::invalid_argument);
}

TEST(Quantise, RoundsHalfUpAndClamps) {
  const cv::Mat v = (cv::Mat_<double>(1, 6) << 0.5, -0.2, 1.3, 0.0, 1.0, 0.5 / 255.0);
  const cv::Mat q8 = quantise(v, 8);
  ASSERT_EQ(q8.type(), CV_16UC1);
  EXPECT_EQ(q8.at<std::uint16_t>(0), 128);  // floor(127.5 + 0.5)
  EXPECT_EQ(q8.at<std::uint16_t>(1), 0);
  EXPECT_EQ(q8.at<std::uint16_t>(2), 255);
  EXPECT_EQ(q8.at<std::uint16_t>(3), 0);
  EXPECT_EQ(q8.at<std::uint16_t>(4), 255);
  EXPECT_EQ(q8.at<std::uint16_t>(5), 1);    // exactly half a code rounds up
  const cv::Mat q10 = quantise(v, 10);
  EXPECT_EQ(q10.at<std::uint16_t>(0), 512);  // floor(511.5 + 0.5)
  EXPECT_EQ(q10.at<std::uint16_t>(2), 1023);
}

TEST(Quantise, EveryCodeSurvivesDequantiseQuantise) {
  for (int bits : {8, 10}) {
    const int n = 1 << bits;
    cv::Mat codes(1, n, CV_16UC3);
    for (int i = 0; i < n; ++i) codes.at<cv::Vec<std::uint16_t, 3>>(i) = {std::uint16_t(i), std::uint16_t(n - 1 - i), std::uint16_t(i)};
    const cv::Mat values = dequantise(codes, bits);
    ASSERT_EQ(values.type(), CV_64FC3);
    EXPECT_DOUBLE_EQ(values.at<cv::Vec3d>(n - 1)[0], 1.0);
    EXPECT_EQ(cv::norm(quantise(values, bits), codes, cv::NORM_INF), 0.0) << bits << " bits";
  }
}

// Through its table (more samples than codes) and by division (fewer), every value is code / (2^bits - 1) exactly,
// and a code out of range is named in the refusal.
// A row at a time (DequantisedRows, as reduce_codes reads D's input) is the same doubles as the whole plane, and the
// codes are checked before any row is read.
TEST(Quantise, DequantisedRowsAreThePlanesRows) {
  for (const int bits : {8, 10, 16}) {
    const int top = (1 << bits) - 1;
    for (const int width : {700, 3}) {  // more samples than codes (the table) and fewer (the division)
      cv::Mat codes(4, width, CV_16UC3);
      for (int k = 0; k < static_cast<int>(codes.total()) * 3; ++k) {
        codes.ptr<std::uint16_t>()[k] = static_cast<std::uint16_t>((k * 7919 + 13) % (top + 1));
      }
      const DequantisedRows rows(codes, bits);
      const cv::Mat plane = dequantise(codes, bits);
      std::vector<double> row(static_cast<std::size_t>(3 * width));
      for (int y = 0; y < codes.rows; ++y) {
        rows.row(y, row.data());
        EXPECT_EQ(std::memcmp(row.data(), plane.ptr(y), row.size() * sizeof(double)), 0) << bits << " bits, row " << y;
      }
    }
  }
  cv::Mat bad(2, 5, CV_16UC3, cv::Scalar(3, 3, 3));
  bad.at<cv::Vec<std::uint16_t, 3>>(1, 4)[2] = 256;
  EXPECT_THROW(DequantisedRows(bad, 8), std::invalid_argument);
  EXPECT_NO_THROW(DequantisedRows(bad, 9));
  EXPECT_THROW(DequantisedRows(bad, 0), std::invalid_argument);
  EXPECT_THROW(DequantisedRows(bad, 40), std::invalid_argument);
  EXPECT_THROW(DequantisedRows(cv::Mat(2, 2, CV_8UC3), 8), std::invalid_argument);
}

TEST(Quantise, DequantiseIsTheDivisionByTableAndDirectly) {
  for (const int bits : {8, 16}) {
    const int top = (1 << bits) - 1;
    cv::Mat codes(3, 700, CV_16UC1);
    for (int k = 0; k < static_cast<int>(codes.total()); ++k) codes.at<std::uint16_t>(k) = static_cast<std::uint16_t>((k * 7919) % (top + 1));
    const cv::Mat values = dequantise(codes, bits);
    for (int k = 0; k < static_cast<int>(codes.total()); ++k) {
      ASSERT_EQ(values.at<double>(k), codes.at<std::uint16_t>(k) / static_cast<double>(top)) << bits << " bits, " << k;
    }
  }
  cv::Mat bad(2, 600, CV_16UC1, cv::Scalar(3));
  bad.at<std::uint16_t>(1, 10) = 300;
  bad.at<std::uint16_t>(1, 20) = 999;
  try {
    dequantise(bad, 8);
    FAIL() << "code 300 at 8 bits was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("code 300 exceeds 8-bit range"), std::string::npos) << e.what();
  }
}

TEST(Quantise, ErrorIsAtMostHalfACode) {
  cv::Mat v(64, 64, CV_64FC3);
  cv::randu(v, 0.0, 1.0);
  for (int bits : {8, 10}) {
    const cv::Mat back = dequantise(quantise(v, bits), bits);
    EXPECT_LE(cv::norm(back, v, cv::NORM_INF), 0.5 / ((1 << bits) - 1) + 1e-15);
  }
}

TEST(Quantise, RejectsNanAndBadArguments) {
  const cv::Mat v = (cv::Mat_<double>(1, 2) << 0.5, std::nan(""));
  EXPECT_THROW(quantise(v, 8), std::invalid_argument);
  EXPECT_THROW(quantise(cv::Mat::zeros(2, 2, CV_64F), 0), std::invalid_argument);
  EXPECT_THROW(quantise(cv::Mat::zeros(2, 2, CV_32F), 8), std::invalid_argument);
  EXPECT_THROW(dequantise(cv::Mat(1, 1, CV_16U, cv::Scalar(256)), 8), std::invalid_argument);
}

TEST(Luma, UsesRec709WeightsOnRgbOrder) {
  cv::Mat rgb(1, 4, CV_64FC3);
  rgb.at<cv::Vec3d>(0) = {1, 0, 0};
  rgb.at<cv::Vec3d>(1) = {0, 1, 0};
  rgb.at<cv::Vec3d>(2) = {0, 0, 1};
  rgb.at<cv::Vec3d>(3) = {0.5, 0.5, 0.5};
  const cv::Mat y = luma(rgb);
  ASSERT_EQ(y.type(), CV_64FC1);
  EXPECT_DOUBLE_EQ(y.at<double>(0), 0.2126);
  EXPECT_DOUBLE_EQ(y.at<double>(1), 0.7152);
  EXPECT_DOUBLE_EQ(y.at<double>(2), 0.0722);
  EXPECT_NEAR(y.at<double>(3), 0.5, 1e-15);
}

}  // namespace
}  // namespace trm
