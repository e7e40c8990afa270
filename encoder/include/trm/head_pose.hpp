// Head poses and the view's projection: what a scene with head rotation exposes (FrameSource::head_view) and what
// the methods that reproject past frames (Kim et al.'s temporal antialiasing, rotational reprojection) use. One
// camera model for the scene that renders the view and the methods that reproject it, so that a reprojection to
// the pose a frame was rendered at lands where the scene would have put the content.
//
// Pixel coordinates are pixel centres: pixel (x, y) is at (x, y), the view's centre at ((W - 1)/2, (H - 1)/2).
// The view looks along +z, x to the right, y down (image rows); rotations are rotational only (no translation),
// so every world point is a direction.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <vector>

namespace trm {

// A pinhole projection with square pixels and the principal point at the view's centre.
struct PinholeView {
  int width = 1;
  int height = 1;
  double focal_px = 1.0;  // focal length in pixels

  // The projection of a view `width` pixels wide seeing `horizontal_fov_deg` degrees across (pixel edges).
  static PinholeView of_fov(int width, int height, double horizontal_fov_deg);
  cv::Point2d centre() const { return {0.5 * (width - 1), 0.5 * (height - 1)}; }
  // The direction (view coordinates, z = 1) through a pixel, and the pixel a direction lands on (z > 0).
  Eigen::Vector3d ray(cv::Point2d pixel) const;
  cv::Point2d pixel(const Eigen::Vector3d& direction) const;
};

// The head's orientation at a frame: the rotation from view to world coordinates.
struct HeadView {
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  PinholeView projection;
};

// Where the direction seen at `pixel` by a head at `from` appears to a head at `to` (same projection).
cv::Point2d reproject_pixel(cv::Point2d pixel, const Eigen::Quaterniond& from, const Eigen::Quaterniond& to,
                            const PinholeView& projection);

// Kim et al. Eq. 1's interpolated pose: slerp from `previous` to `current` by d (d = 0: previous, d = 1: current).
Eigen::Quaterniond interpolated_orientation(const Eigen::Quaterniond& previous, const Eigen::Quaterniond& current,
                                            double d);

// The angle between two orientations, in degrees.
double rotation_angle_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

// The head's orientation between the poses of consecutive frames, and where a fixated world direction is on the
// display meanwhile: what the eye of a viewer holding a world point still on the retina follows (the vestibulo-ocular
// reflex with pursuit) while the head rotates. Frame f's pose is the head at f · period_s (the frame's start, when its
// content is rendered); between two frames the head turns at a constant rate along the shortest arc
// (interpolated_orientation), so a turn at a constant angular velocity is exact at every instant, not only at the
// frame starts. Before the first pose and after the last the head holds them.
class HeadPath {
 public:
  // At least one orientation; period_s finite and > 0. Throws std::invalid_argument naming the argument.
  HeadPath(std::vector<Eigen::Quaterniond> frame_orientations, double period_s);
  Eigen::Quaterniond orientation_at(double t_s) const;
  // Where the world direction a head at the first pose sees at `pixel` appears at time t (reproject_pixel from the
  // first pose to orientation_at(t)); t_s finite, else std::invalid_argument.
  cv::Point2d fixated_pixel(cv::Point2d pixel, double t_s, const PinholeView& projection) const;
  double period_s() const { return period_s_; }
  std::size_t frames() const { return orientations_.size(); }

 private:
  std::vector<Eigen::Quaterniond> orientations_;
  double period_s_ = 0.0;
};

// The bilinear interpolation of a CV_64FC3 or CV_32FC3 image at (x, y) (sample (i, j) at coordinate (i, j)), the
// indices clamped (replicate border). Exact in double: OpenCV's remap and warp functions quantise the fraction to
// 1/32 pixel, as large as the head jitter's motion per frame.
cv::Vec3d bilinear_at(const cv::Mat& image, double x, double y);

// `frame` (CV_64FC3 or CV_32FC3) rendered with the head at `rendered`, as a head at `wanted` sees it:
// every pixel of the wanted view samples the rendered frame where its direction was (reproject_pixel), bilinear;
// directions outside the rendered view take its nearest edge pixel (edge replication fills the holes). CV_64FC3.
cv::Mat reproject_view(const cv::Mat& frame, const Eigen::Quaterniond& rendered, const Eigen::Quaterniond& wanted,
                       const PinholeView& projection);

}  // namespace trm
