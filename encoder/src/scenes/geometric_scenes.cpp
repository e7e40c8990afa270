// Scenes drawn from closed-form geometry: discs, line, zoneplate, checker, flash, square.
// Every pixel value is the box-filter average (over the pixel square) of the continuous linear-light
// scene: exactly where the integral is closed-form, by supersampling where it is not.
#include "scenes/scene_support.hpp"
#include "scenes/scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace trm::scenes {
namespace {

// Position on a loop of length `period`, in [0, period).
double wrap(double x, double period) {
  const double r = std::fmod(x, period);
  return r < 0.0 ? r + period : r;
}

// --- discs (paper Exp. 1, Fig. 10): high-contrast discs moving horizontally on black ----------------
class DiscsScene final : public AnalyticScene {
 public:
  explicit DiscsScene(const SceneParams& p) : AnalyticScene("discs", p) {
    radius_ = std::max(0.75, 0.06 * std::min(p.width, p.height));
    period_ = p.width + 2.0 * radius_;  // a disc fully leaves the view before it re-enters
  }

  cv::Mat linear_frame(std::int64_t t) override {
    cv::Mat frame(height(), width(), CV_64FC3, cv::Scalar::all(0.0));
    for (const Disc& d : discs_at(t)) draw(frame, d);
    return frame;
  }

  Motion motion(std::int64_t t) const override {
    Motion m;
    for (const Disc& d : discs_at(t)) {
      m.objects.push_back({cv::Rect2d(d.cx - radius_, d.cy - radius_, 2 * radius_, 2 * radius_), cv::Vec2d(d.vx, 0.0)});
    }
    return m;
  }

 private:
  static constexpr int kCount = 4;
  struct Disc {
    double cx, cy, vx;
    cv::Vec3d colour;
  };

  // Row k moves at (0.2 + 0.2 k) view widths per second, alternating direction; copies that overlap the
  // view after wrapping are all returned.
  std::vector<Disc> discs_at(std::int64_t t) const {
    static const std::array<cv::Vec3d, kCount> colours{cv::Vec3d(1, 1, 1), cv::Vec3d(1.0, 0.85, 0.1),
                                                       cv::Vec3d(0.1, 0.9, 1.0), cv::Vec3d(1, 1, 1)};
    const double time = seconds(t);
    std::vector<Disc> out;
    for (int k = 0; k < kCount; ++k) {
      const double speed = (0.2 + 0.2 * k) * width() * (k % 2 == 0 ? 1.0 : -1.0);
      const double start = period_ * k / kCount;
      const double cx = wrap(start + speed * time, period_) - radius_;
      const double cy = height() * (k + 1.0) / (kCount + 1.0);
      for (double copy : {cx - period_, cx, cx + period_}) {
        if (copy + radius_ > 0.0 && copy - radius_ < width()) out.push_back({copy, cy, speed, colours[static_cast<std::size_t>(k)]});
      }
    }
    return out;
  }

  // Coverage-weighted "over" compositing. Pixels whose square lies entirely inside or outside the disc
  // (centre distance beyond R -/+ half the diagonal) are exact; only edge pixels are supersampled.
  void draw(cv::Mat& frame, const Disc& d) const {
    const int ss = params().supersample;
    const double half_diag = std::numbers::sqrt2 / 2.0;
    const int x0 = std::max(0, static_cast<int>(std::floor(d.cx - radius_)));
    const int x1 = std::min(width() - 1, static_cast<int>(std::ceil(d.cx + radius_)));
    const int y0 = std::max(0, static_cast<int>(std::floor(d.cy - radius_)));
    const int y1 = std::min(height() - 1, static_cast<int>(std::ceil(d.cy + radius_)));
    const double r2 = radius_ * radius_;
    for (int y = y0; y <= y1; ++y) {
      cv::Vec3d* row = frame.ptr<cv::Vec3d>(y);
      for (int x = x0; x <= x1; ++x) {
        const double dist = std::hypot(x + 0.5 - d.cx, y + 0.5 - d.cy);
        double coverage;
        if (dist <= radius_ - half_diag) {
          coverage = 1.0;
        } else if (dist >= radius_ + half_diag) {
          continue;
        } else {
          int inside = 0;
          for (int j = 0; j < ss; ++j) {
            const double sy = y + (j + 0.5) / ss - d.cy;
            for (int i = 0; i < ss; ++i) {
              const double sx = x + (i + 0.5) / ss - d.cx;
              inside += (sx * sx + sy * sy <= r2) ? 1 : 0;
            }
          }
          coverage = static_cast<double>(inside) / (ss * ss);
        }
        row[x] = row[x] * (1.0 - coverage) + d.colour * coverage;
      }
    }
  }

  double radius_;
  double period_;
};

// --- line (paper Fig. 12): a one-pixel-wide white vertical line moving left to right on black ---------
class LineScene final : public AnalyticScene {
 public:
  explicit LineScene(const SceneParams& p) : AnalyticScene("line", p) {}

  cv::Mat linear_frame(std::int64_t t) override {
    // Exact box filter: a column's value is the length of [x, x + 1) covered by the line.
    cv::Mat row(1, width(), CV_64FC1, cv::Scalar(0.0));
    for (double left : copies(t)) {
      const int first = std::max(0, static_cast<int>(std::floor(left)));
      const int last = std::min(width() - 1, static_cast<int>(std::ceil(left + kWidth)));
      for (int x = first; x <= last; ++x) {
        row.at<double>(x) += std::max(0.0, std::min<double>(x + 1, left + kWidth) - std::max<double>(x, left));
      }
    }
    cv::Mat rgb_row(1, width(), CV_64FC3);
    for (int x = 0; x < width(); ++x) rgb_row.at<cv::Vec3d>(x) = cv::Vec3d::all(std::min(1.0, row.at<double>(x)));
    cv::Mat frame;
    cv::repeat(rgb_row, height(), 1, frame);
    return frame;
  }

  Motion motion(std::int64_t t) const override {
    Motion m;
    for (double left : copies(t)) m.objects.push_back({cv::Rect2d(left, 0, kWidth, height()), cv::Vec2d(speed(), 0.0)});
    return m;
  }

 private:
  static constexpr double kWidth = 1.0;  // full-resolution pixels: the thinnest line the panel shows
  double speed() const { return 0.5 * width(); }  // half a view width per second
  double period() const { return width() + kWidth; }
  std::vector<double> copies(std::int64_t t) const {
    const double left = wrap(0.25 * width() + speed() * seconds(t), period()) - kWidth;
    std::vector<double> out;
    for (double c : {left - period(), left, left + period()}) {
      if (c + kWidth > 0.0 && c < width()) out.push_back(c);
    }
    return out;
  }
};

// --- zoneplate: I = 1/2 + 1/2 cos(a r^2), reaching the Nyquist frequency at r = max(W, H) / 2 --------
// The centre sways horizontally (so the pattern moves). Because cos(a(dx^2 + dy^2)) =
// cos(a dx^2) cos(a dy^2) - sin(a dx^2) sin(a dy^2), the box filter over a pixel square is separable:
// it is built from 1-D pixel averages of cos and sin, each integrated by supersampling.
class ZoneplateScene final : public AnalyticScene {
 public:
  explicit ZoneplateScene(const SceneParams& p)
      : AnalyticScene("zoneplate", p), chirp_(std::numbers::pi / std::max(p.width, p.height)) {}

  cv::Mat linear_frame(std::int64_t t) override {
    const double cx = centre_x(seconds(t)), cy = 0.5 * height();
    std::vector<double> cos_x, sin_x, cos_y, sin_y;
    pixel_averages(width(), cx, cos_x, sin_x);
    pixel_averages(height(), cy, cos_y, sin_y);
    cv::Mat frame(height(), width(), CV_64FC3);
    for (int y = 0; y < height(); ++y) {
      cv::Vec3d* row = frame.ptr<cv::Vec3d>(y);
      for (int x = 0; x < width(); ++x) {
        const double c = cos_x[static_cast<std::size_t>(x)] * cos_y[static_cast<std::size_t>(y)] -
                         sin_x[static_cast<std::size_t>(x)] * sin_y[static_cast<std::size_t>(y)];
        row[x] = cv::Vec3d::all(std::clamp(0.5 + 0.5 * c, 0.0, 1.0));
      }
    }
    return frame;
  }

  Motion motion(std::int64_t t) const override {
    const double omega = 2.0 * std::numbers::pi * kSwayHz;
    Motion m;
    m.global_velocity_px_s = {amplitude() * omega * std::cos(omega * seconds(t)), 0.0};
    return m;
  }

 private:
  static constexpr double kSwayHz = 0.25;
  double amplitude() const { return width() / 8.0; }
  double centre_x(double time) const {
    return 0.5 * width() + amplitude() * std::sin(2.0 * std::numbers::pi * kSwayHz * time);
  }
  void pixel_averages(int n, double centre, std::vector<double>& cos_avg, std::vector<double>& sin_avg) const {
    // The chirp reaches (and in the corners exceeds) the Nyquist frequency, and 1-D samples are cheap:
    // integrate with four times the requested supersampling, at least 16 points per pixel.
    const int ss = std::max(16, 4 * params().supersample);
    cos_avg.assign(static_cast<std::size_t>(n), 0.0);
    sin_avg.assign(static_cast<std::size_t>(n), 0.0);
    for (int p = 0; p < n; ++p) {
      for (int k = 0; k < ss; ++k) {
        const double d = p + (k + 0.5) / ss - centre;
        cos_avg[static_cast<std::size_t>(p)] += std::cos(chirp_ * d * d) / ss;
        sin_avg[static_cast<std::size_t>(p)] += std::sin(chirp_ * d * d) / ss;
      }
    }
  }
  double chirp_;  // a in cos(a r^2): local frequency a r / pi cycles per pixel
};

// --- checker: the Nyquist checkerboard (1-pixel cells), still -----------------------------------------
class CheckerScene final : public AnalyticScene {
 public:
  explicit CheckerScene(const SceneParams& p) : AnalyticScene("checker", p) {}
  cv::Mat linear_frame(std::int64_t t) override {
    seconds(t);  // validates t
    cv::Mat frame(height(), width(), CV_64FC3);
    for (int y = 0; y < height(); ++y) {
      cv::Vec3d* row = frame.ptr<cv::Vec3d>(y);
      for (int x = 0; x < width(); ++x) row[x] = cv::Vec3d::all(((x + y) % 2 == 0) ? 1.0 : 0.0);
    }
    return frame;
  }
  Motion motion(std::int64_t) const override { return {}; }
};

// --- flash: all-black on even frames, all-white on odd frames (the extremes of the range) -------------
class FlashScene final : public AnalyticScene {
 public:
  explicit FlashScene(const SceneParams& p) : AnalyticScene("flash", p) {}
  cv::Mat linear_frame(std::int64_t t) override {
    seconds(t);
    return cv::Mat(height(), width(), CV_64FC3, cv::Scalar::all(t % 2 == 0 ? 0.0 : 1.0));
  }
  Motion motion(std::int64_t) const override { return {}; }
};

// --- square (supplement §1.1): a square of one luminance sliding over a background of another ---------
class SquareScene final : public AnalyticScene {
 public:
  SquareScene(const SceneParams& p, const MovingSquare& square) : AnalyticScene("square", p) {
    side_ = square.side_px.value_or(std::max(1.0, 0.25 * std::min(p.width, p.height)));
    speed_ = square.speed_px_s.value_or(0.5 * p.width);
    start_ = square.start_left_px.value_or(0.5 * (p.width - side_));
    if (!(std::isfinite(side_) && side_ > 0.0)) throw std::invalid_argument("scene 'square': the side must be a finite number of pixels > 0");
    if (!std::isfinite(speed_)) throw std::invalid_argument("scene 'square': the speed must be a finite number of pixels per second");
    if (!std::isfinite(start_)) throw std::invalid_argument("scene 'square': the start position must be finite");
    if (!(square.contrast >= 0.0 && square.contrast <= 1.0)) {
      throw std::invalid_argument("scene 'square': the Michelson contrast must be in [0, 1]");
    }
    bright_ = 0.5 * (1.0 + square.contrast);
    dark_ = 0.5 * (1.0 - square.contrast);
    period_ = p.width + side_;
  }

  // Coverage is separable: the fraction of a pixel's column interval the square covers times that of its row
  // interval, so the box filter is exact.
  cv::Mat linear_frame(std::int64_t t) override {
    std::vector<double> across(static_cast<std::size_t>(width()), 0.0);
    for (double left : copies(t)) {
      for (int x = std::max(0, static_cast<int>(std::floor(left)));
           x < std::min(width(), static_cast<int>(std::ceil(left + side_))); ++x) {
        across[static_cast<std::size_t>(x)] += overlap(x, left, left + side_);
      }
    }
    const double top = 0.5 * (height() - side_);
    cv::Mat frame(height(), width(), CV_64FC3);
    for (int y = 0; y < height(); ++y) {
      const double down = overlap(y, top, top + side_);
      cv::Vec3d* row = frame.ptr<cv::Vec3d>(y);
      for (int x = 0; x < width(); ++x) {
        const double coverage = std::min(1.0, across[static_cast<std::size_t>(x)]) * down;
        row[x] = cv::Vec3d::all(dark_ + (bright_ - dark_) * coverage);
      }
    }
    return frame;
  }

  Motion motion(std::int64_t t) const override {
    Motion m;
    for (double left : copies(t)) {
      m.objects.push_back({cv::Rect2d(left, 0.5 * (height() - side_), side_, side_), cv::Vec2d(speed_, 0.0)});
    }
    return m;
  }

 private:
  static double overlap(int pixel, double begin, double end) {
    return std::max(0.0, std::min<double>(pixel + 1, end) - std::max<double>(pixel, begin));
  }
  // The square's left edge at t and the wrapped copies that overlap the view.
  std::vector<double> copies(std::int64_t t) const {
    const double left = wrap(start_ + side_ + speed_ * seconds(t), period_) - side_;
    std::vector<double> out;
    for (double c : {left - period_, left, left + period_}) {
      if (c + side_ > 0.0 && c < width()) out.push_back(c);
    }
    return out;
  }

  double side_ = 0, speed_ = 0, start_ = 0, bright_ = 0, dark_ = 0, period_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> make_square(const SceneParams& p) { return std::make_unique<SquareScene>(p, MovingSquare{}); }
std::unique_ptr<FrameSource> make_discs(const SceneParams& p) { return std::make_unique<DiscsScene>(p); }
std::unique_ptr<FrameSource> make_line(const SceneParams& p) { return std::make_unique<LineScene>(p); }
std::unique_ptr<FrameSource> make_zoneplate(const SceneParams& p) { return std::make_unique<ZoneplateScene>(p); }
std::unique_ptr<FrameSource> make_checker(const SceneParams& p) { return std::make_unique<CheckerScene>(p); }
std::unique_ptr<FrameSource> make_flash(const SceneParams& p) { return std::make_unique<FlashScene>(p); }

}  // namespace trm::scenes

namespace trm {
std::unique_ptr<FrameSource> make_moving_square(const SceneParams& params, const MovingSquare& square) {
  return std::make_unique<scenes::SquareScene>(params, square);
}
}  // namespace trm
