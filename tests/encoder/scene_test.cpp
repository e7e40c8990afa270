// Analytic scenes: size, range, determinism, motion, and the exactness of their anti-aliasing.
#include "trm/media.hpp"
#include "trm/scene.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <cstdio>
#include <numbers>
#include <unistd.h>

namespace trm {
namespace {

SceneParams small_params(int w, int h, double hz = 90.0) {
  SceneParams p;
  p.width = w;
  p.height = h;
  p.refresh_hz = hz;
  return p;
}

bool in_unit_range(const cv::Mat& m) { return cv::checkRange(m, true, nullptr, 0.0, 1.0 + 1e-15); }

double max_diff(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

TEST(Scenes, AllNamesAreRegistered) {
  const std::vector<std::string> expected{"discs", "text", "panorama", "line", "zoneplate", "checker", "flash", "static", "jitter", "headturn", "square"};
  EXPECT_EQ(scene_names(), expected);
}

TEST(Scenes, RenderTheRequestedSizeInRangeForAnySize) {
  for (const std::string& name : scene_names()) {
    for (auto [w, h] : {std::pair{37, 23}, std::pair{1, 1}, std::pair{2, 5}, std::pair{64, 48}}) {
      auto scene = make_scene(name, small_params(w, h));
      EXPECT_EQ(scene->name(), name);
      EXPECT_EQ(scene->width(), w);
      EXPECT_EQ(scene->height(), h);
      EXPECT_FALSE(scene->frame_count().has_value());
      for (std::int64_t t : {0, 1, 17}) {
        const cv::Mat f = scene->linear_frame(t);
        ASSERT_EQ(f.type(), CV_64FC3) << name;
        ASSERT_EQ(f.size(), cv::Size(w, h)) << name;
        EXPECT_TRUE(in_unit_range(f)) << name << " " << w << "x" << h << " t=" << t;
      }
    }
  }
}

TEST(Scenes, AreDeterministicForAGivenSeed) {
  for (const std::string& name : scene_names()) {
    auto a = make_scene(name, small_params(48, 40));
    auto b = make_scene(name, small_params(48, 40));
    // Different access orders must not change the frames (jitter memoises its random walk).
    const cv::Mat b9 = b->linear_frame(9);
    EXPECT_EQ(max_diff(a->linear_frame(0), b->linear_frame(0)), 0.0) << name;
    EXPECT_EQ(max_diff(a->linear_frame(9), b9), 0.0) << name;
  }
}

TEST(Scenes, MovingScenesChangeAndStillScenesDoNot) {
  for (const char* name : {"discs", "text", "panorama", "line", "zoneplate", "flash", "jitter"}) {
    auto s = make_scene(name, small_params(64, 48));
    // Jitter moves by hundredths of a pixel at this size (0.05 degrees over a 100-degree, 64-px view).
    const double least_change = std::string(name) == "jitter" ? 1e-6 : 1e-3;
    EXPECT_GT(max_diff(s->linear_frame(0), s->linear_frame(1)), least_change) << name;
  }
  for (const char* name : {"static", "checker"}) {
    auto s = make_scene(name, small_params(64, 48));
    EXPECT_EQ(max_diff(s->linear_frame(0), s->linear_frame(1)), 0.0) << name;
    EXPECT_EQ(max_diff(s->linear_frame(0), s->linear_frame(1000)), 0.0) << name;
    const Motion m = s->motion(3);
    EXPECT_EQ(m.global_velocity_px_s, cv::Vec2d(0, 0));
    EXPECT_TRUE(m.objects.empty());
  }
}

TEST(Scenes, SeedChangesTheRandomScenes) {
  for (const char* name : {"panorama", "static", "jitter"}) {
    SceneParams p = small_params(40, 30);
    auto a = make_scene(name, p);
    p.seed = 99;
    auto b = make_scene(name, p);
    EXPECT_GT(max_diff(a->linear_frame(2), b->linear_frame(2)), 1e-3) << name;
  }
}

TEST(Scenes, RejectBadParametersAndNames) {
  try {
    make_scene("nope", SceneParams{});
    FAIL() << "unknown scene accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("panorama"), std::string::npos) << "message should list valid scenes";
  }
  SceneParams p = small_params(0, 10);
  EXPECT_THROW(make_scene("discs", p), std::invalid_argument);
  p = small_params(10, 10, 0.0);
  EXPECT_THROW(make_scene("line", p), std::invalid_argument);
  p = small_params(10, 10, std::nan(""));
  EXPECT_THROW(make_scene("line", p), std::invalid_argument);
  p = small_params(10, 10);
  p.supersample = 0;
  EXPECT_THROW(make_scene("text", p), std::invalid_argument);
  EXPECT_THROW(make_scene("discs", small_params(8, 8))->linear_frame(-1), std::invalid_argument);
}

TEST(FlashAndChecker, AreTheExtremes) {
  auto flash = make_scene("flash", small_params(5, 3));
  EXPECT_EQ(cv::countNonZero(flash->linear_frame(0).reshape(1)), 0);
  EXPECT_EQ(cv::norm(flash->linear_frame(1), cv::Mat(3, 5, CV_64FC3, cv::Scalar::all(1.0)), cv::NORM_INF), 0.0);
  auto checker = make_scene("checker", small_params(5, 4));
  const cv::Mat c = checker->linear_frame(0);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) EXPECT_EQ(c.at<cv::Vec3d>(y, x)[1], (x + y) % 2 == 0 ? 1.0 : 0.0);
}

// The line is one pixel wide: the exact box filter spreads exactly one unit of light over each row.
TEST(Line, BoxFilterConservesTheLineExactly) {
  auto line = make_scene("line", small_params(101, 7, 90.0));
  for (std::int64_t t = 0; t < 40; ++t) {
    const cv::Mat f = line->linear_frame(t);
    const Motion m = line->motion(t);
    ASSERT_FALSE(m.objects.empty());
    const cv::Rect2d& b = m.objects.front().bounds;
    EXPECT_DOUBLE_EQ(m.objects.front().velocity_px_s[0], 50.5);  // half the view width per second
    if (b.x < 0 || b.x + b.width > 101) continue;  // wrapping across the border
    for (int y = 0; y < 7; ++y) EXPECT_NEAR(cv::sum(f.row(y))[0], 1.0, 1e-12) << "t=" << t;
    const int left = static_cast<int>(std::floor(b.x));
    EXPECT_NEAR(f.at<cv::Vec3d>(3, left)[0], left + 1 - b.x, 1e-12);
  }
}

// Each disc occupies its own row band, so the light inside its box is its colour times its area.
TEST(Discs, CoverageMatchesTheDiscArea) {
  SceneParams p = small_params(200, 150);
  p.supersample = 8;
  auto discs = make_scene("discs", p);
  for (std::int64_t t : {0, 5, 11}) {
    const cv::Mat f = discs->linear_frame(t);
    const Motion m = discs->motion(t);
    ASSERT_FALSE(m.objects.empty());
    int checked = 0;
    for (const MotionObject& o : m.objects) {
      EXPECT_NE(o.velocity_px_s[0], 0.0);
      const cv::Rect box(static_cast<int>(std::floor(o.bounds.x)) - 1, static_cast<int>(std::floor(o.bounds.y)) - 1,
                         static_cast<int>(std::ceil(o.bounds.width)) + 3, static_cast<int>(std::ceil(o.bounds.height)) + 3);
      if (box.x < 0 || box.y < 0 || box.x + box.width > f.cols || box.y + box.height > f.rows) continue;
      const double radius = o.bounds.width / 2;
      const double area = std::numbers::pi * radius * radius;
      const cv::Scalar light = cv::sum(f(box));
      const double brightest = std::max({light[0], light[1], light[2]});
      EXPECT_NEAR(brightest / area, 1.0, 0.01) << "t=" << t;  // every disc has one channel at 1
      ++checked;
    }
    EXPECT_GT(checked, 0);
  }
}

// Panning by whole pixels is an exact shift; by half a pixel, the exact box filter of the texture.
TEST(Panorama, SubPixelPanIsTheExactBoxFilter) {
  // Speed is a quarter view width per second: 16 px/s at W = 64.
  auto whole = make_scene("panorama", small_params(64, 20, 16.0));  // 1 px per frame
  const cv::Mat a = whole->linear_frame(0), b = whole->linear_frame(1);
  EXPECT_EQ(max_diff(b.colRange(0, 63), a.colRange(1, 64)), 0.0);
  EXPECT_EQ(whole->motion(0).global_velocity_px_s, cv::Vec2d(-16.0, 0.0));
  auto half = make_scene("panorama", small_params(64, 20, 32.0));  // 0.5 px per frame
  const cv::Mat h0 = half->linear_frame(0), h1 = half->linear_frame(1), h2 = half->linear_frame(2);
  const cv::Mat expected = 0.5 * (h0.colRange(0, 63) + h2.colRange(0, 63));
  EXPECT_LE(max_diff(h1.colRange(0, 63), expected), 1e-15);
}

TEST(Text, ScrollsUpByExactRowShifts) {
  auto text = make_scene("text", small_params(80, 48, 12.0));  // a quarter height per second: 1 row per frame
  const cv::Mat a = text->linear_frame(0), b = text->linear_frame(1);
  EXPECT_LE(max_diff(b.rowRange(0, 47), a.rowRange(1, 48)), 1e-12);
  EXPECT_EQ(text->motion(0).global_velocity_px_s, cv::Vec2d(0.0, -12.0));
  // Text has ink: not uniformly white.
  double lo, hi;
  cv::minMaxLoc(a.reshape(1), &lo, &hi);
  EXPECT_LT(lo, 0.5);
  EXPECT_EQ(hi, 1.0);
}

// The separable box-filter construction against brute-force 2-D supersampling of the same chirp.
TEST(Zoneplate, MatchesBruteForceSupersampling) {
  const int w = 40, h = 30;
  SceneParams p = small_params(w, h);
  auto zone = make_scene("zoneplate", p);
  const cv::Mat f = zone->linear_frame(0);  // centre at (W/2, H/2) at t = 0
  const double a = std::numbers::pi / std::max(w, h);
  const int n = 64;
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double acc = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double dx = x + (i + 0.5) / n - 0.5 * w, dy = y + (j + 0.5) / n - 0.5 * h;
          acc += 0.5 + 0.5 * std::cos(a * (dx * dx + dy * dy));
        }
      worst = std::max(worst, std::abs(acc / (n * n) - f.at<cv::Vec3d>(y, x)[0]));
    }
  std::printf("zoneplate vs 64x64 brute force: max |diff| = %.3g\n", worst);
  // Midpoint rule with 16 vs 64 points per axis; the corners exceed Nyquist. Measured 5.6e-4.
  EXPECT_LT(worst, 2e-3);
  EXPECT_NE(zone->motion(1).global_velocity_px_s[0], 0.0);
}

TEST(Jitter, MovesByTinyRandomAmountsAndReportsIt) {
  auto jitter = make_scene("jitter", small_params(108, 60));
  double largest_speed = 0;
  for (std::int64_t t = 0; t < 30; ++t) largest_speed = std::max(largest_speed, cv::norm(jitter->motion(t).global_velocity_px_s));
  EXPECT_GT(largest_speed, 0.0);
  // At 108 px over a 100 degree view, 0.05 degree standard deviation is ~0.05 px: frames differ slightly.
  const double change = max_diff(jitter->linear_frame(0), jitter->linear_frame(1));
  EXPECT_GT(change, 0.0);
  EXPECT_LT(change, 0.5);
}

TEST(Scenes, MotionScaleRunsEveryMotionThatManyTimesAsFast) {
  for (const std::string name : {"discs", "line", "zoneplate", "text", "panorama", "headturn"}) {
    SceneParams fast = small_params(40, 24);
    fast.motion_scale = 2.0;
    auto scaled = make_scene(name, fast);
    auto native = make_scene(name, small_params(40, 24));
    // Frame t at twice the speed is frame 2t of the scene (to the rounding of t / refresh x 2 against 2t / refresh).
    for (const std::int64_t t : {1, 3}) EXPECT_LT(max_diff(scaled->linear_frame(t), native->linear_frame(2 * t)), 1e-9) << name;
    const Motion a = scaled->motion(2), b = native->motion(4);
    EXPECT_NEAR(a.global_velocity_px_s[0], 2.0 * b.global_velocity_px_s[0], 1e-9) << name;
    ASSERT_EQ(a.objects.size(), b.objects.size()) << name;
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
      EXPECT_NEAR(a.objects[i].velocity_px_s[0], 2.0 * b.objects[i].velocity_px_s[0], 1e-9) << name;
    }
    SceneParams frozen = small_params(40, 24);
    frozen.motion_scale = 0.0;
    auto still = make_scene(name, frozen);
    EXPECT_EQ(max_diff(still->linear_frame(5), still->linear_frame(0)), 0.0) << name;
  }
  for (const std::string name : {"static", "checker", "flash", "jitter"}) {
    SceneParams p = small_params(8, 8);
    p.motion_scale = 2.0;
    EXPECT_THROW(make_scene(name, p), std::invalid_argument) << name;
  }
  SceneParams bad = small_params(8, 8);
  bad.motion_scale = std::nan("");
  EXPECT_THROW(make_scene("discs", bad), std::invalid_argument);
  bad.motion_scale = -1.0;
  EXPECT_THROW(make_scene("discs", bad), std::invalid_argument);
}

TEST(StaticScene, ShowsTheGivenImageInLinearLight) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("trm_static_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  cv::Mat bgr(6, 8, CV_8UC3);
  cv::randu(bgr, 0, 256);
  const std::string file = (dir / "still.png").string();
  ASSERT_TRUE(media::write_image(file, bgr));
  SceneParams p = small_params(8, 6);
  p.image_path = file;
  auto s = make_scene("static", p);
  const cv::Mat f = s->linear_frame(4);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(f.at<cv::Vec3d>(y, x)[c], to_linear(bgr.at<cv::Vec3b>(y, x)[2 - c] / 255.0, Transfer::Srgb), 1e-12);
  // The panorama accepts the same image.
  auto pano = make_scene("panorama", p);
  EXPECT_TRUE(in_unit_range(pano->linear_frame(3)));
  p.image_path = (dir / "missing.png").string();
  EXPECT_THROW(make_scene("static", p), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace trm

namespace trm {
namespace {

// The supplement's square: luminances 0.5 (1 ± c) and an exact box filter, so the light above the background sums to
// side^2 c at any sub-pixel position, and the square's left edge moves by speed / refresh per frame.
TEST(Scenes, MovingSquareIsExactAtSubPixelPositions) {
  SceneParams p = small_params(64, 40, 90.0);
  MovingSquare square;
  square.side_px = 10.5;
  square.speed_px_s = 90.0 * 1.25;  // 1.25 pixels per frame
  square.start_left_px = 7.3;
  square.contrast = 0.2;
  auto scene = make_moving_square(p, square);
  for (std::int64_t t : {0, 1, 5}) {
    const cv::Mat f = scene->linear_frame(t);
    cv::Mat grey;
    cv::extractChannel(f, grey, 0);
    const double dark = 0.5 * (1.0 - 0.2);
    EXPECT_NEAR(cv::sum(grey - dark)[0], 10.5 * 10.5 * 0.2, 1e-9) << t;
    double lo = 0, hi = 0;
    cv::minMaxLoc(grey, &lo, &hi);
    EXPECT_NEAR(lo, dark, 1e-12);
    EXPECT_NEAR(hi, 0.5 * 1.2, 1e-12);
    const Motion m = scene->motion(t);
    ASSERT_EQ(m.objects.size(), 1u);
    EXPECT_NEAR(m.objects[0].bounds.x, 7.3 + 1.25 * static_cast<double>(t), 1e-9);
    EXPECT_DOUBLE_EQ(m.objects[0].velocity_px_s[0], 112.5);
  }
  square.contrast = 1.5;
  EXPECT_THROW(make_moving_square(p, square), std::invalid_argument);
  square.contrast = 0.2;
  square.side_px = 0.0;
  EXPECT_THROW(make_moving_square(p, square), std::invalid_argument);
}

}  // namespace
}  // namespace trm
