#include "trm/head_pose.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace trm {

PinholeView PinholeView::of_fov(int width, int height, double horizontal_fov_deg) {
  if (width < 1 || height < 1) throw std::invalid_argument("pinhole view: the size must be at least 1x1");
  if (!(horizontal_fov_deg > 0.0 && horizontal_fov_deg < 180.0)) {
    throw std::invalid_argument("pinhole view: the field of view must be in (0, 180) degrees, got " +
                                std::to_string(horizontal_fov_deg));
  }
  PinholeView view;
  view.width = width;
  view.height = height;
  view.focal_px = 0.5 * width / std::tan(0.5 * horizontal_fov_deg * std::numbers::pi / 180.0);
  return view;
}

Eigen::Vector3d PinholeView::ray(cv::Point2d p) const {
  const cv::Point2d c = centre();
  return {(p.x - c.x) / focal_px, (p.y - c.y) / focal_px, 1.0};
}

cv::Point2d PinholeView::pixel(const Eigen::Vector3d& d) const {
  const cv::Point2d c = centre();
  return {c.x + focal_px * d.x() / d.z(), c.y + focal_px * d.y() / d.z()};
}

cv::Point2d reproject_pixel(cv::Point2d pixel, const Eigen::Quaterniond& from, const Eigen::Quaterniond& to,
                            const PinholeView& projection) {
  return projection.pixel(to.conjugate() * (from * projection.ray(pixel)));
}

Eigen::Quaterniond interpolated_orientation(const Eigen::Quaterniond& previous, const Eigen::Quaterniond& current,
                                            double d) {
  return previous.slerp(d, current);
}

double rotation_angle_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180.0 / std::numbers::pi;
}

HeadPath::HeadPath(std::vector<Eigen::Quaterniond> frame_orientations, double period_s)
    : orientations_(std::move(frame_orientations)), period_s_(period_s) {
  if (orientations_.empty()) throw std::invalid_argument("HeadPath: frame_orientations must hold at least one pose");
  if (!(std::isfinite(period_s) && period_s > 0.0)) {
    throw std::invalid_argument("HeadPath: period_s must be finite and > 0, got " + std::to_string(period_s));
  }
}

Eigen::Quaterniond HeadPath::orientation_at(double t_s) const {
  if (!std::isfinite(t_s)) throw std::invalid_argument("HeadPath: t_s must be finite");
  const double frame = t_s / period_s_;
  if (frame <= 0.0) return orientations_.front();
  const auto last = static_cast<double>(orientations_.size() - 1);
  if (frame >= last) return orientations_.back();
  const double start = std::floor(frame);
  const auto f = static_cast<std::size_t>(start);
  return interpolated_orientation(orientations_[f], orientations_[f + 1], frame - start);
}

cv::Point2d HeadPath::fixated_pixel(cv::Point2d pixel, double t_s, const PinholeView& projection) const {
  return reproject_pixel(pixel, orientations_.front(), orientation_at(t_s), projection);
}

namespace {

template <typename Pixel>
cv::Vec3d bilinear_of(const cv::Mat& image, double x, double y) {
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, std::max(0, image.cols - 2));
  const int j = std::clamp(static_cast<int>(std::floor(y)), 0, std::max(0, image.rows - 2));
  const int i1 = std::min(i + 1, image.cols - 1), j1 = std::min(j + 1, image.rows - 1);
  const double fx = std::clamp(x - i, 0.0, 1.0), fy = std::clamp(y - j, 0.0, 1.0);
  const auto* top = image.ptr<Pixel>(j);
  const auto* bottom = image.ptr<Pixel>(j1);
  cv::Vec3d out;
  for (int ch = 0; ch < 3; ++ch) {
    out[ch] = (1 - fy) * ((1 - fx) * top[i][ch] + fx * top[i1][ch]) + fy * ((1 - fx) * bottom[i][ch] + fx * bottom[i1][ch]);
  }
  return out;
}

}  // namespace

cv::Vec3d bilinear_at(const cv::Mat& image, double x, double y) {
  if (image.type() == CV_64FC3) return bilinear_of<cv::Vec3d>(image, x, y);
  if (image.type() == CV_32FC3) return bilinear_of<cv::Vec3f>(image, x, y);
  throw std::invalid_argument("bilinear_at: the image must be CV_64FC3 or CV_32FC3");
}

cv::Mat reproject_view(const cv::Mat& frame, const Eigen::Quaterniond& rendered, const Eigen::Quaterniond& wanted,
                       const PinholeView& projection) {
  if (frame.cols != projection.width || frame.rows != projection.height) {
    throw std::invalid_argument("reproject_view: a " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                                " frame for a " + std::to_string(projection.width) + "x" +
                                std::to_string(projection.height) + " view");
  }
  if (frame.type() != CV_64FC3 && frame.type() != CV_32FC3) {
    throw std::invalid_argument("reproject_view: the frame must be CV_64FC3 or CV_32FC3");
  }
  // One homography K R_rendered^-1 R_wanted K^-1 maps every pixel of the wanted view into the rendered one.
  const Eigen::Matrix3d rotation = (rendered.conjugate() * wanted).normalized().toRotationMatrix();
  const cv::Point2d c = projection.centre();
  const double f = projection.focal_px;
  cv::Mat out(frame.size(), CV_64FC3);
  for (int y = 0; y < frame.rows; ++y) {
    auto* row = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < frame.cols; ++x) {
      const Eigen::Vector3d d = rotation * projection.ray({static_cast<double>(x), static_cast<double>(y)});
      // A direction behind the rendered view is no pixel of it: its nearest edge is what replication gives.
      const double z = std::max(d.z(), 1e-9);
      row[x] = bilinear_at(frame, c.x + f * d.x() / z, c.y + f * d.y() / z);
    }
  }
  return out;
}

}  // namespace trm
