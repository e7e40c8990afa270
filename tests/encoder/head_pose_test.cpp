// Head poses and rotational reprojection (trm/head_pose.hpp) against the pinhole camera's analytic pixel shift, and
// the head-rotation scenes (jitter, headturn) against their own poses.
#include "trm/head_pose.hpp"
#include "trm/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace trm {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Quaterniond yaw(double degrees) { return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kDeg, Eigen::Vector3d::UnitY())); }

// A pure yaw by theta moves the direction at angle alpha = atan(u) from the axis to alpha - theta: the pixel lands
// at c + f tan(alpha - theta), its row scaled by cos(alpha) / cos(alpha - theta).
cv::Point2d analytic_yaw_shift(cv::Point2d p, double theta_deg, const PinholeView& view) {
  const cv::Point2d c = view.centre();
  const double alpha = std::atan((p.x - c.x) / view.focal_px);
  const double theta = theta_deg * kDeg;
  return {c.x + view.focal_px * std::tan(alpha - theta),
          c.y + (p.y - c.y) * std::cos(alpha) / std::cos(alpha - theta)};
}

TEST(HeadPose, PinholeViewOfAFieldOfViewSpansItAcrossThePixelEdges) {
  const PinholeView view = PinholeView::of_fov(1080, 1200, 100.0);
  EXPECT_NEAR(view.focal_px, 540.0 / std::tan(50.0 * kDeg), 1e-9);
  // The left edge of pixel 0 (x = -0.5) is 50 degrees off the axis.
  EXPECT_NEAR(std::atan((-0.5 - view.centre().x) / view.focal_px) / kDeg, -50.0, 1e-9);
  EXPECT_THROW(PinholeView::of_fov(0, 10, 90.0), std::invalid_argument);
  EXPECT_THROW(PinholeView::of_fov(10, 10, 180.0), std::invalid_argument);
}

TEST(HeadPose, ReprojectionOfAPureRotationMapsEveryPixelToItsAnalyticShift) {
  const PinholeView view = PinholeView::of_fov(1080, 1200, 100.0);
  double worst = 0.0;
  for (const double theta : {0.05, -0.3, 2.0, 10.0}) {
    for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(539.5, 599.5), cv::Point2d(1079, 17), cv::Point2d(200, 1199)}) {
      const cv::Point2d got = reproject_pixel(p, Eigen::Quaterniond::Identity(), yaw(theta), view);
      const cv::Point2d want = analytic_yaw_shift(p, theta, view);
      worst = std::max({worst, std::abs(got.x - want.x), std::abs(got.y - want.y)});
    }
  }
  EXPECT_LT(worst, 1e-9);
  // Back and forth is the identity; the same rotation applied to both poses changes nothing.
  const cv::Point2d p(123.25, 456.75);
  const Eigen::Quaterniond a = yaw(3.0) * Eigen::Quaterniond(Eigen::AngleAxisd(0.7 * kDeg, Eigen::Vector3d::UnitX()));
  const cv::Point2d there = reproject_pixel(p, a, yaw(-1.0), view);
  const cv::Point2d back = reproject_pixel(there, yaw(-1.0), a, view);
  EXPECT_NEAR(back.x, p.x, 1e-9);
  EXPECT_NEAR(back.y, p.y, 1e-9);
}

TEST(HeadPose, SlerpOfTwoYawsIsTheYawInBetween) {
  for (const double d : {0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0}) {
    const Eigen::Quaterniond between = interpolated_orientation(yaw(-1.0), yaw(2.0), d);
    EXPECT_NEAR(rotation_angle_deg(between, yaw(-1.0 + 3.0 * d)), 0.0, 1e-6) << d;
  }
  EXPECT_NEAR(rotation_angle_deg(yaw(0.25), yaw(-0.5)), 0.75, 1e-9);
}

// A head turning at a constant rate, known only at the frame starts: between them the fixated direction is where the
// analytic turn puts it at that instant (c + f tan(alpha - omega t)), at every sub-frame time, not only at the frames.
TEST(HeadPath, ConstantRateYawPutsTheFixatedPointAtTheAnalyticShiftAtEveryInstant) {
  const PinholeView view = PinholeView::of_fov(540, 600, 100.0);
  const double rate_deg_s = 10.0, period = 1.0 / 90.0;
  std::vector<Eigen::Quaterniond> poses;
  for (int f = 0; f <= 8; ++f) poses.push_back(yaw(rate_deg_s * f * period));
  const HeadPath path(poses, period);
  double worst = 0.0;
  for (const cv::Point2d p : {view.centre(), cv::Point2d(12.0, 40.0), cv::Point2d(500.5, 599.0)}) {
    for (int step = 0; step <= 8 * 16; ++step) {
      const double t = step * period / 16.0;
      const cv::Point2d got = path.fixated_pixel(p, t, view);
      const cv::Point2d want = analytic_yaw_shift(p, rate_deg_s * t, view);
      worst = std::max({worst, std::abs(got.x - want.x), std::abs(got.y - want.y)});
    }
  }
  EXPECT_LT(worst, 1e-9);
  // Outside the poses the head holds them.
  EXPECT_EQ(path.fixated_pixel(view.centre(), -1.0, view), path.fixated_pixel(view.centre(), 0.0, view));
  EXPECT_NEAR(path.fixated_pixel(view.centre(), 1.0, view).x, analytic_yaw_shift(view.centre(), rate_deg_s * 8 * period, view).x,
              1e-9);
}

TEST(HeadPath, StillHeadKeepsTheFixatedPointWhereItIs) {
  const PinholeView view = PinholeView::of_fov(216, 240, 100.0);
  const Eigen::Quaterniond rest = yaw(0.3) * Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * kDeg, Eigen::Vector3d::UnitX()));
  const HeadPath path(std::vector<Eigen::Quaterniond>(5, rest), 1.0 / 90.0);
  const cv::Point2d p(33.25, 101.5);
  for (const double t : {0.0, 0.004, 0.0111, 0.03, 0.5}) {
    const cv::Point2d got = path.fixated_pixel(p, t, view);
    EXPECT_NEAR(got.x, p.x, 1e-12) << t;
    EXPECT_NEAR(got.y, p.y, 1e-12) << t;
  }
  EXPECT_THROW(HeadPath({}, 0.01), std::invalid_argument);
  EXPECT_THROW(HeadPath({rest}, 0.0), std::invalid_argument);
  EXPECT_THROW((void)path.orientation_at(std::nan("")), std::invalid_argument);
}

TEST(HeadPose, ReprojectedViewSamplesTheRenderedOneAtTheAnalyticShiftAndReplicatesItsEdge) {
  // A linear ramp is reproduced exactly by bilinear interpolation, so the reprojected view is the ramp evaluated
  // at the analytic source pixel.
  const PinholeView view = PinholeView::of_fov(160, 90, 100.0);
  const double ax = 1.0 / 200.0, ay = 1.0 / 400.0;
  cv::Mat ramp(view.height, view.width, CV_64FC3);
  for (int y = 0; y < ramp.rows; ++y) {
    for (int x = 0; x < ramp.cols; ++x) ramp.at<cv::Vec3d>(y, x) = cv::Vec3d::all(0.1 + ax * x + ay * y);
  }
  const double theta = 4.0;  // rendered at the identity, wanted at yaw theta: the wanted view looks right
  const cv::Mat shown = reproject_view(ramp, Eigen::Quaterniond::Identity(), yaw(theta), view);
  double worst = 0.0;
  int replicated = 0;
  for (int y = 0; y < shown.rows; ++y) {
    for (int x = 0; x < shown.cols; ++x) {
      // Pixel (x, y) of the wanted view shows the direction the rendered view had at the inverse shift.
      const cv::Point2d source = analytic_yaw_shift(cv::Point2d(x, y), -theta, view);
      const double sx = std::clamp(source.x, 0.0, view.width - 1.0), sy = std::clamp(source.y, 0.0, view.height - 1.0);
      replicated += source.x > view.width - 1.0;
      worst = std::max(worst, std::abs(shown.at<cv::Vec3d>(y, x)[1] - (0.1 + ax * sx + ay * sy)));
    }
  }
  EXPECT_GT(replicated, 0);  // the right edge's hole, filled by the last column
  EXPECT_LT(worst, 1e-12);
  EXPECT_THROW(reproject_view(ramp, yaw(0), yaw(1), PinholeView::of_fov(10, 10, 90.0)), std::invalid_argument);
}

SceneParams params_of(int w, int h) {
  SceneParams p;
  p.width = w;
  p.height = h;
  return p;
}

TEST(HeadRotationScenes, ExposeTheirPosesAndRenderWhatReprojectionPredicts) {
  for (const char* name : {"jitter", "headturn"}) {
    auto scene = make_scene(name, params_of(216, 120));
    for (const char* other : {"panorama", "discs", "static"}) {
      EXPECT_FALSE(make_scene(other, params_of(16, 16))->head_view(0)) << other;
    }
    const auto a = scene->head_view(3), b = scene->head_view(4);
    ASSERT_TRUE(a && b) << name;
    EXPECT_GT(rotation_angle_deg(a->orientation, b->orientation), 0.0) << name;
    EXPECT_NEAR(a->projection.focal_px, PinholeView::of_fov(216, 120, 100.0).focal_px, 1e-12) << name;
    // Frame 3 rotated to frame 4's pose is frame 4, inside the view (bilinear of the texture's box filter again:
    // a blur of a fraction of a pixel, no misregistration).
    const cv::Mat predicted = reproject_view(scene->linear_frame(3), a->orientation, b->orientation, a->projection);
    const cv::Rect inner(8, 8, 200, 104);
    const cv::Mat actual = scene->linear_frame(4);
    const double err = cv::norm(predicted(inner), actual(inner), cv::NORM_L2) / std::sqrt(inner.area() * 3.0);
    const double held = cv::norm(scene->linear_frame(3)(inner), actual(inner), cv::NORM_L2) / std::sqrt(inner.area() * 3.0);
    EXPECT_LT(err, 0.35 * held) << name << ": reprojected RMS " << err << ", held " << held;
  }
}

TEST(HeadRotationScenes, HeadTurnSweepsAtItsRateAndReportsTheCentresVelocity) {
  auto scene = make_scene("headturn", params_of(108, 60));
  const auto pose = [&](std::int64_t t) { return scene->head_view(t)->orientation; };
  // 10 degrees per second at 90 Hz: 1/9 degree per frame while the sweep rises.
  EXPECT_NEAR(rotation_angle_deg(pose(0), pose(9)), 1.0, 1e-9);
  EXPECT_NEAR(rotation_angle_deg(pose(0), pose(72)), 8.0, 1e-9);   // the sweep's end
  EXPECT_NEAR(rotation_angle_deg(pose(0), pose(144)), 0.0, 1e-9);  // back at the start, turning left
  const double f = scene->head_view(0)->projection.focal_px;
  EXPECT_NEAR(scene->motion(0).global_velocity_px_s[0], -10.0 * kDeg * f, 1e-9);
  EXPECT_LT(scene->motion(100).global_velocity_px_s[0] * scene->motion(10).global_velocity_px_s[0], 0.0);
}

}  // namespace
}  // namespace trm
