// JPEG-LS through CharLS: lossless round trips, strict decoding, and as a link payload coding.
#include "trm/jpegls.hpp"
#include "trm/link.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <iostream>
#include <random>

namespace trm::link {
namespace {

using test_support::same_codes;
using test_support::synthetic_codes;

// A smooth image (a blurred gradient with a few discs): compressible as rendered content is.
cv::Mat smooth_codes(int width, int height, int bits) {
  cv::Mat img(height, width, CV_64FC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      img.at<cv::Vec3d>(y, x) = cv::Vec3d(static_cast<double>(x) / width, static_cast<double>(y) / height, 0.5);
  for (int i = 0; i < 5; ++i)
    cv::circle(img, {width * (i + 1) / 6, height / 2}, height / 6, cv::Scalar(0.9, 0.2 * i, 0.1), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(img, img, {0, 0}, 1.5);
  cv::Mat codes;
  img.convertTo(codes, CV_16UC3, (1 << bits) - 1);
  return codes;
}

TEST(JpegLs, LosslessAtEightAndTenBitsAndOddSizes) {
  for (int bits : {8, 10}) {
    for (cv::Size size : {cv::Size(1, 1), cv::Size(97, 61), cv::Size(160, 90)}) {
      for (const cv::Mat& codes : {synthetic_codes(size.width, size.height, bits, 3), smooth_codes(size.width, size.height, bits)}) {
        const std::vector<std::uint8_t> coded = jpegls_encode(codes, bits);
        const cv::Mat decoded = jpegls_decode(coded, size.width, size.height, bits);
        EXPECT_TRUE(same_codes(decoded, codes)) << bits << " bits " << size;
      }
    }
  }
}

TEST(JpegLs, SmoothContentCompresses) {
  for (int bits : {8, 10}) {
    const cv::Mat codes = smooth_codes(320, 180, bits);
    const double bpp = bits_per_pixel(jpegls_encode(codes, bits).size(), codes.total());
    EXPECT_LT(bpp, 3.0 * bits / 2) << bits;  // at least 2:1 on smooth content
    std::cout << "JPEG-LS smooth 320x180 at " << bits << " bits: " << bpp << " bpp (raw " << 3 * bits << ")\n";
  }
}

TEST(JpegLs, DecodeTrustsNothing) {
  const cv::Mat codes = synthetic_codes(20, 10, 8, 1);
  const std::vector<std::uint8_t> coded = jpegls_encode(codes, 8);
  EXPECT_THROW(jpegls_decode(coded, 21, 10, 8), JpegLsError);  // other size
  EXPECT_THROW(jpegls_decode(coded, 20, 10, 10), JpegLsError);  // other depth
  EXPECT_THROW(jpegls_decode({}, 20, 10, 8), JpegLsError);
  std::vector<std::uint8_t> cut(coded.begin(), coded.begin() + static_cast<std::ptrdiff_t>(coded.size() / 2));
  try {  // refused before CharLS sees it (CharLS itself can take seconds on a stream cut inside the scan)
    (void)jpegls_decode(cut, 20, 10, 8);
    ADD_FAILURE() << "truncated stream decoded";
  } catch (const JpegLsError& e) {
    EXPECT_NE(std::string(e.what()).find("end-of-image marker"), std::string::npos) << e.what();
  }
  std::vector<std::uint8_t> garbage(100, 0xFF);
  EXPECT_THROW(jpegls_decode(garbage, 20, 10, 8), JpegLsError);
  std::mt19937 rng(1);
  for (int i = 0; i < 300; ++i) {  // random damage: an error or some image, never a crash
    std::vector<std::uint8_t> damaged = coded;
    damaged[rng() % damaged.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    try {
      (void)jpegls_decode(damaged, 20, 10, 8);
    } catch (const JpegLsError&) {
    }
  }
  cv::Mat too_big = codes.clone();
  too_big.at<cv::Vec3w>(0, 0)[0] = 256;
  EXPECT_THROW(jpegls_encode(too_big, 8), std::invalid_argument);
  EXPECT_THROW(jpegls_encode(codes, 12), std::invalid_argument);
}

TEST(JpegLs, AsLinkPayloadPerSliceAndPerFrame) {
  for (int lines : {1, 16, 1 << 16}) {  // per line, per 16-line slice, per frame
    Transmitter tx({lines, 0, PayloadCoding::JpegLs});
    Receiver rx;
    std::vector<LinkFrame> views;
    for (int t = 0; t < 2; ++t) views.push_back(test_support::make_view(t, 0, 97, 61, 0.5, 10, false));
    ViewBits total;
    for (const LinkFrame& v : views) {
      const SentView sent = tx.send(v);
      total += sent.bits;
      for (const auto& p : sent.packets) ASSERT_EQ(rx.push(p), PushResult::Accepted);
    }
    rx.flush();
    const auto frames = rx.take_frames();
    ASSERT_EQ(frames.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_TRUE(frames[i].complete());
      EXPECT_TRUE(same_codes(frames[i].codes, views[i].codes));
    }
    EXPECT_EQ(total.pixel_bits, (97u * 61 + 49 * 31) * 30);
  }
  // A damaged JPEG-LS slice loses its lines and nothing else.
  Transmitter tx({16, 0, PayloadCoding::JpegLs});
  const LinkFrame v = test_support::make_view(0, 0, 40, 40, 0.5, 8);
  SentView sent = tx.send(v);
  ASSERT_EQ(sent.packets.size(), 3u);  // 16 + 16 + 8 lines
  Receiver rx;
  rx.push(sent.packets[0]);
  rx.push(sent.packets[2]);
  rx.flush();
  const ReceivedFrame f = rx.take_frames().at(0);
  EXPECT_EQ(f.intact_lines(), 24);
  EXPECT_EQ(f.line_intact[15], 1);
  EXPECT_EQ(f.line_intact[16], 0);
  EXPECT_EQ(f.line_intact[31], 0);
  EXPECT_EQ(f.line_intact[32], 1);
}

TEST(JpegLs, TallyCountsPerDisplayedPixel) {
  LosslessTally full_rate, trm;
  for (int t = 0; t < 2; ++t) {
    LinkFrame full = test_support::make_view(0, 0, 64, 48, 1.0, 8, false);  // t = 0 parity: full
    full.codes = smooth_codes(64, 48, 8);
    full_rate.add(full);
    LinkFrame v = test_support::make_view(t, 0, 64, 48, 0.5, 8, false);
    v.codes = smooth_codes(v.meta.width, v.meta.height, 8);
    trm.add(v);
  }
  EXPECT_EQ(full_rate.displayed_pixels, 2u * 64 * 48);
  EXPECT_EQ(trm.displayed_pixels, 2u * 64 * 48);
  EXPECT_EQ(trm.sent_pixels, 64u * 48 + 32 * 24);
  EXPECT_LT(trm.bits_per_displayed_pixel(), full_rate.bits_per_displayed_pixel());
  EXPECT_GT(trm.bits_per_displayed_pixel(), 0.0);
}

}  // namespace
}  // namespace trm::link
