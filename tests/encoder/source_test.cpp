// Image sequences and video files: decoding to linear RGB, ordering, and clear errors for bad input.
#include "trm/media.hpp"
#include "trm/scene.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace trm {
namespace {

namespace fs = std::filesystem;

// A fresh directory per test, removed afterwards.
class SourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("trm_src_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const cv::Mat& img) const { ASSERT_TRUE(media::write_image(path(name), img)) << name; }
  // Float TIFF without compression: OpenCV's default for 3-channel float is lossy SGILOG (LogLuv).
  void write_float_tiff(const std::string& name, const cv::Mat& img) const {
    ASSERT_TRUE(media::write_image(path(name), img, {cv::IMWRITE_TIFF_COMPRESSION, 1})) << name;
  }

  // Expects `fn` to throw E whose message names `needle`.
  template <typename E, typename F>
  void expect_error_naming(F fn, const std::string& needle) const {
    try {
      fn();
      ADD_FAILURE() << "no exception; expected one naming " << needle;
    } catch (const E& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "message: " << e.what();
    }
  }

  fs::path dir_;
};

cv::Mat solid_bgr8(int w, int h, int b, int g, int r) { return cv::Mat(h, w, CV_8UC3, cv::Scalar(b, g, r)); }

TEST_F(SourceTest, ReadsEightBitColourAsLinearRgbSortedByName) {
  write("f_2.png", solid_bgr8(4, 3, 10, 20, 30));
  write("f_10.png", solid_bgr8(4, 3, 200, 100, 50));  // "f_10" sorts before "f_2"
  write("other.png", solid_bgr8(9, 9, 0, 0, 0));       // not matched by the pattern
  auto seq = open_image_sequence(path("f_*.png"));
  ASSERT_EQ(seq->frame_count(), 2);
  EXPECT_EQ(seq->width(), 4);
  EXPECT_EQ(seq->height(), 3);
  const cv::Mat first = seq->linear_frame(0);
  ASSERT_EQ(first.type(), CV_64FC3);
  EXPECT_DOUBLE_EQ(first.at<cv::Vec3d>(1, 2)[0], to_linear(50 / 255.0, Transfer::Srgb));  // R from BGR's third
  EXPECT_DOUBLE_EQ(first.at<cv::Vec3d>(1, 2)[2], to_linear(200 / 255.0, Transfer::Srgb));
  EXPECT_DOUBLE_EQ(seq->linear_frame(1).at<cv::Vec3d>(0, 0)[0], to_linear(30 / 255.0, Transfer::Srgb));
  EXPECT_THROW(seq->linear_frame(2), std::out_of_range);
  EXPECT_EQ(seq->motion(0).global_velocity_px_s, cv::Vec2d(0, 0));
}

TEST_F(SourceTest, ReadsSixteenBitGreyAndDropsAlpha) {
  write("g_1.png", cv::Mat(2, 3, CV_16UC1, cv::Scalar(40000)));
  auto grey = open_image_sequence(path("g_?.png"));
  const cv::Vec3d v = grey->linear_frame(0).at<cv::Vec3d>(1, 1);
  EXPECT_DOUBLE_EQ(v[0], to_linear(40000 / 65535.0, Transfer::Srgb));
  EXPECT_EQ(v[0], v[1]);
  EXPECT_EQ(v[1], v[2]);
  write("a_1.png", cv::Mat(2, 3, CV_8UC4, cv::Scalar(255, 0, 0, 7)));  // opaque-blue BGRA, alpha 7
  const cv::Vec3d blue = open_image_sequence(path("a_1.png"))->linear_frame(0).at<cv::Vec3d>(0, 0);
  EXPECT_EQ(blue, cv::Vec3d(0.0, 0.0, 1.0));
}

TEST_F(SourceTest, FloatImagesAreLinearAndMustBeFiniteAndInRange) {
  cv::Mat ok(2, 2, CV_32FC3, cv::Scalar(0.25, 0.5, 0.75));
  write_float_tiff("lin_0.tiff", ok);
  const cv::Vec3d v = open_image_sequence(path("lin_*.tiff"))->linear_frame(0).at<cv::Vec3d>(1, 1);
  EXPECT_DOUBLE_EQ(v[0], 0.75);  // BGR on disk -> RGB, no transfer function applied
  EXPECT_DOUBLE_EQ(v[2], 0.25);
  for (float bad : {std::nanf(""), -0.5f, 3.0f, INFINITY}) {
    cv::Mat img = ok.clone();
    img.at<cv::Vec3f>(1, 0)[1] = bad;
    write_float_tiff("bad_0.tiff", img);
    expect_error_naming<std::invalid_argument>([&] { open_image_sequence(path("bad_*.tiff")); }, "bad_0.tiff");
  }
}

TEST_F(SourceTest, ZeroMatchesAndMissingDirectoriesAreReported) {
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("none_*.png")); }, "none_*.png");
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("nodir/x_*.png")); }, "nodir");
}

TEST_F(SourceTest, MixedSizesNameTheOffendingFile) {
  write("m_1.png", solid_bgr8(4, 3, 1, 2, 3));
  write("m_2.png", solid_bgr8(4, 3, 1, 2, 3));
  write("m_3.png", solid_bgr8(5, 3, 1, 2, 3));
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("m_*.png")); }, "m_3.png");
}

TEST_F(SourceTest, NonImageFilesNameTheOffendingFile) {
  write("n_1.png", solid_bgr8(4, 3, 1, 2, 3));
  std::ofstream(path("n_2.png")) << "this is not a PNG";
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("n_*.png")); }, "n_2.png");
}

// Found by fuzz/fuzz_image.cpp: OpenCV hands a file with the DICOM signature to GDCM, which aborted the
// process (a failed assertion) on this 132-byte file instead of failing the read.
TEST_F(SourceTest, DicomFilesAreRefusedBeforeOpenCvAbortsOnThem) {
  std::ofstream(path("d_1.png"), std::ios::binary) << std::string(128, '\0') << "DICM";
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("d_1.png")); }, "d_1.png");
  expect_error_naming<std::runtime_error>([&] { open_image_sequence(path("d_1.png")); }, "DICOM");
}

TEST_F(SourceTest, VideoFramesAreReadInAnyOrder) {
  const std::string file = path("clip.avi");
  media::VideoWriter writer;
  constexpr int kMjpg = 'M' | ('J' << 8) | ('P' << 16) | ('G' << 24);  // cv::VideoWriter::fourcc's packing
  if (!writer.open(file, kMjpg, 30.0, cv::Size(32, 16))) GTEST_SKIP() << "this OpenCV build cannot write MJPG/AVI";
  for (int i = 0; i < 5; ++i) writer.write(solid_bgr8(32, 16, 40 * i, 40 * i, 40 * i));
  writer.release();

  auto video = open_video(file);
  EXPECT_EQ(video->width(), 32);
  EXPECT_EQ(video->height(), 16);
  ASSERT_TRUE(video->frame_count().has_value());
  EXPECT_EQ(*video->frame_count(), 5);
  // Lossy codec: compare the mean grey level against the encoded value, within a few codes.
  auto grey_code = [](const cv::Mat& linear) { return to_encoded(cv::mean(linear)[1], Transfer::Srgb) * 255.0; };
  EXPECT_NEAR(grey_code(video->linear_frame(3)), 120.0, 4.0);
  EXPECT_NEAR(grey_code(video->linear_frame(1)), 40.0, 4.0);  // backwards: reopen and skip
  EXPECT_NEAR(grey_code(video->linear_frame(4)), 160.0, 4.0);
  EXPECT_THROW(video->linear_frame(50), std::runtime_error);
}

TEST_F(SourceTest, BadVideoFilesAreReported) {
  expect_error_naming<std::runtime_error>([&] { open_video(path("missing.mp4")); }, "missing.mp4");
  std::ofstream(path("junk.avi")) << "not a video";
  expect_error_naming<std::runtime_error>([&] { open_video(path("junk.avi")); }, "junk.avi");
}

}  // namespace
}  // namespace trm
