// Kim et al.'s temporal antialiasing blend (trm/kim_taa.hpp): the part the `kim` and `kim-trm` methods share.
#include "trm/kim_taa.hpp"

#include "trm/frame.hpp"
#include "trm/transfer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace trm {

namespace {

// The pinhole projection assumed for a scene that exposes no head poses (nothing is reprojected there).
constexpr double kDefaultFovDeg = 100.0;

double parse_number(const std::string& key, const std::string& text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    throw std::invalid_argument("method 'kim': " + key + "='" + text + "' is not a finite number");
  }
  return value;
}

}  // namespace

const char* const kKimOptionHelp =
    "d=D,n=N,hmax=DEG_S,wmin=W,wlb=W (any of them; defaults d=0.6667, n=1, hmax=25, wmin=0.3, wlb=0.1)";

void KimParameters::validate() const {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("method 'kim': " + what); };
  if (!(d >= 0.0 && d <= 1.0)) fail("d must be in [0, 1], got " + std::to_string(d));
  if (n < 1 || n > kMaxSamples) fail("n must be in [1, " + std::to_string(kMaxSamples) + "], got " + std::to_string(n));
  if (!(std::isfinite(h_max_deg_s) && h_max_deg_s > 0.0)) {
    fail("hmax must be finite and > 0, got " + std::to_string(h_max_deg_s));
  }
  if (!(w_lb >= 0.0 && w_lb <= w_min && w_min <= 1.0)) {
    fail("the weights must satisfy 0 <= wlb <= wmin <= 1, got wlb=" + std::to_string(w_lb) +
         ", wmin=" + std::to_string(w_min));
  }
}

KimParameters parse_kim_parameters(const std::string& option) {
  KimParameters p;
  if (option.empty()) return p;
  std::stringstream items(option);
  std::string item;
  while (std::getline(items, item, ',')) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::invalid_argument("method 'kim': option '" + item + "' is not KEY=VALUE (" + kKimOptionHelp + ")");
    }
    const std::string key = item.substr(0, eq);
    const std::string value = item.substr(eq + 1);
    if (key == "d") {
      p.d = parse_number(key, value);
    } else if (key == "n") {
      const double count = parse_number(key, value);
      if (count != std::floor(count) || count < 1 || count > KimParameters::kMaxSamples) {
        throw std::invalid_argument("method 'kim': n must be a whole number in [1, " +
                                    std::to_string(KimParameters::kMaxSamples) + "], got " + value);
      }
      p.n = static_cast<int>(count);
    } else if (key == "hmax") {
      p.h_max_deg_s = parse_number(key, value);
    } else if (key == "wmin") {
      p.w_min = parse_number(key, value);
    } else if (key == "wlb") {
      p.w_lb = parse_number(key, value);
    } else {
      throw std::invalid_argument("method 'kim': unknown option '" + key + "' (" + kKimOptionHelp + ")");
    }
  }
  p.validate();
  return p;
}

double kim_current_weight(double h, double w_min, double h_max) {
  if (h > h_max) return 1.0;
  const double ease = -0.5 * (std::cos(std::numbers::pi * h / h_max) - 1.0);
  return (1.0 - w_min) * ease * ease + w_min;
}

double kim_local_min_weight(double colour_change, double w_min, double w_lb) {
  return w_min - (w_min - w_lb) * colour_change;
}

KimBlend::KimBlend(const KimParameters& parameters, double refresh_hz, const FrameSource* scene)
    : parameters_(parameters), refresh_hz_(refresh_hz), scene_(scene) {
  parameters_.validate();
  validate_refresh_hz(refresh_hz_, "method 'kim': refresh rate");
}

Eigen::Quaterniond KimBlend::orientation(std::int64_t t) const {
  const std::optional<HeadView> view = scene_ ? scene_->head_view(t) : std::nullopt;
  return view ? view->orientation : Eigen::Quaterniond::Identity();
}

PinholeView KimBlend::projection(cv::Size size) const {
  const std::optional<HeadView> view = scene_ ? scene_->head_view(0) : std::nullopt;
  if (view && view->projection.width == size.width && view->projection.height == size.height) return view->projection;
  return PinholeView::of_fov(size.width, size.height, kDefaultFovDeg);
}

cv::Mat KimBlend::dynamic_mask(std::int64_t t, cv::Size size) const {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  // A scene moved by the head holds a still world; a recorded input's motion is unknown (none is marked).
  if (!scene_ || scene_->head_view(t)) return mask;
  const Motion motion = scene_->motion(t);
  if (motion.global_velocity_px_s != cv::Vec2d(0.0, 0.0)) {
    mask.setTo(255);
    return mask;
  }
  constexpr double kMarginPx = 2.0;  // the rasterised map's anti-aliased border
  for (const MotionObject& object : motion.objects) {
    if (object.velocity_px_s == cv::Vec2d(0.0, 0.0)) continue;
    // Where the object is at t and where it was at t - 1.
    const cv::Point2d back(-object.velocity_px_s[0] / refresh_hz_, -object.velocity_px_s[1] / refresh_hz_);
    for (const cv::Rect2d& r : {object.bounds, cv::Rect2d(object.bounds.tl() + back, object.bounds.size())}) {
      const int x0 = std::clamp(static_cast<int>(std::floor(r.x - kMarginPx)), 0, size.width);
      const int y0 = std::clamp(static_cast<int>(std::floor(r.y - kMarginPx)), 0, size.height);
      const int x1 = std::clamp(static_cast<int>(std::ceil(r.x + r.width + kMarginPx)), 0, size.width);
      const int y1 = std::clamp(static_cast<int>(std::ceil(r.y + r.height + kMarginPx)), 0, size.height);
      if (x1 > x0 && y1 > y0) mask(cv::Rect(x0, y0, x1 - x0, y1 - y0)).setTo(255);
    }
  }
  return mask;
}

cv::Mat KimBlend::blend(const cv::Mat& current, std::int64_t t, int eye) {
  if (current.type() != CV_64FC3 || current.empty()) throw std::invalid_argument("kim: the render must be CV_64FC3");
  History& past = history_[eye];
  const Eigen::Quaterniond now = orientation(t);
  const bool follows = past.t == t - 1 && past.output.size() == current.size();
  if (!follows) {
    past = History{t, current.clone(), now};
    return current.clone();
  }
  const PinholeView view = projection(current.size());
  // Eqs. 1 and 2: the previous output read where the interpolated heads saw this frame's directions.
  double weight_sum = 0.0;
  for (int i = 0; i < parameters_.n; ++i) weight_sum += parameters_.d * (i + 1) / parameters_.n;
  cv::Mat past_colour = cv::Mat::zeros(current.size(), CV_64FC3);
  for (int i = 0; i < parameters_.n; ++i) {
    const double d_i = parameters_.d * (i + 1) / parameters_.n;
    // With d = 0 in every sample the weights are 0/0: the past samples share one location, weigh them equally.
    const double w_i = weight_sum > 0.0 ? d_i / weight_sum : 1.0 / parameters_.n;
    const Eigen::Quaterniond between = interpolated_orientation(past.orientation, now, d_i);
    cv::scaleAdd(reproject_view(past.output, between, now, view), w_i, past_colour, past_colour);
  }
  // Eqs. 3-5, per pixel.
  const double h = rotation_angle_deg(past.orientation, now) * refresh_hz_;
  const cv::Mat dynamic = dynamic_mask(t, current.size());
  const cv::Mat current_encoded = to_encoded(current, Transfer::Srgb);
  const cv::Mat past_encoded = to_encoded(cv::min(cv::max(past_colour, 0.0), 1.0), Transfer::Srgb);
  cv::Mat out(current.size(), CV_64FC3);
  for (int y = 0; y < current.rows; ++y) {
    const auto* c = current.ptr<cv::Vec3d>(y);
    const auto* p = past_colour.ptr<cv::Vec3d>(y);
    const auto* ce = current_encoded.ptr<cv::Vec3d>(y);
    const auto* pe = past_encoded.ptr<cv::Vec3d>(y);
    const auto* moving = dynamic.ptr<std::uint8_t>(y);
    auto* o = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < current.cols; ++x) {
      if (moving[x]) {
        o[x] = c[x];
        continue;
      }
      const double change = std::min(1.0, cv::norm(ce[x] - pe[x]) / std::sqrt(3.0));
      const double a = kim_current_weight(h, kim_local_min_weight(change, parameters_.w_min, parameters_.w_lb),
                                          parameters_.h_max_deg_s);
      o[x] = (1.0 - a) * p[x] + a * c[x];
    }
  }
  past = History{t, out.clone(), now};
  return out;
}

}  // namespace trm
