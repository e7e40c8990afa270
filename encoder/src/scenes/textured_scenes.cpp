// Scenes built on an image or texture: scrolling text, panorama, static image, head jitter and head turn.
// Content is a piecewise-constant texture (one constant per texel, itself box-filtered when it was made),
// moved by sub-pixel amounts; each output pixel is the exact box-filter average over its square.
#include "scenes/scene_support.hpp"
#include "scenes/scenes.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace trm::scenes {
namespace {

using scene_support::box_shift;
using scene_support::procedural_texture;

// Texture for panorama / static / jitter: the user's image, or the procedural one.
cv::Mat texture_of_height(const SceneParams& p, int min_width, int height) {
  if (!p.image_path.empty()) {
    cv::Mat scaled = scene_support::fit_height(scene_support::load_linear_image(p.image_path), height);
    cv::Mat as_float;
    scaled.convertTo(as_float, CV_32FC3);
    return as_float;
  }
  return procedural_texture(min_width, height, p.seed, p.supersample);
}

// --- text (paper Exp. 1, Fig. 10): black text on white scrolling upwards ------------------------------
// The text is drawn once, at `supersample` times the resolution, onto a tape that repeats vertically. The
// tape is box-filtered horizontally to pixel columns and kept as prefix sums over its sub-rows, so the
// vertical box integral over any (fractional) scroll offset is a difference of two interpolated sums.
class TextScene final : public AnalyticScene {
 public:
  explicit TextScene(const SceneParams& p) : AnalyticScene("text", p) { build_tape(); }

  cv::Mat linear_frame(std::int64_t t) override {
    const int ss = params().supersample;
    const double offset = speed() * seconds(t);  // full pixels the tape has moved up
    cv::Mat frame(height(), width(), CV_64FC3);
    for (int y = 0; y < height(); ++y) {
      const double a = (y + offset) * ss;  // pixel row y covers tape sub-rows [a, a + ss)
      cv::Vec3d* row = frame.ptr<cv::Vec3d>(y);
      for (int x = 0; x < width(); ++x) row[x] = cv::Vec3d::all(0.0);
      accumulate_integral(a + ss, +1.0 / ss, row);
      accumulate_integral(a, -1.0 / ss, row);
      for (int x = 0; x < width(); ++x) row[x] = cv::Vec3d::all(std::clamp(row[x][0], 0.0, 1.0));
    }
    return frame;
  }

  Motion motion(std::int64_t) const override {
    Motion m;
    m.global_velocity_px_s = {0.0, -speed()};
    return m;
  }

 private:
  double speed() const { return 0.25 * height(); }  // a quarter of the view height per second

  // row += scale * F(s), F = integral of the periodic tape from sub-row 0 to s (per column).
  void accumulate_integral(double s, double scale, cv::Vec3d* row) const {
    const double n = static_cast<double>(sub_rows_);
    const double periods = std::floor(s / n);
    const double r = s - periods * n;
    const int k = std::min(sub_rows_ - 1, static_cast<int>(std::floor(r)));
    const double f = r - k;
    const double* s0 = prefix_.ptr<double>(k);
    const double* s1 = prefix_.ptr<double>(k + 1);
    const double* total = prefix_.ptr<double>(sub_rows_);
    for (int x = 0; x < width(); ++x) row[x][0] += scale * (periods * total[x] + s0[x] + f * (s1[x] - s0[x]));
  }

  void build_tape() {
    const int ss = params().supersample;
    const int line_px = std::max(4, static_cast<int>(std::lround(height() / 40.0)));
    const int lines = (height() + line_px - 1) / line_px + 2;
    sub_rows_ = lines * line_px * ss;
    cv::Mat ink(sub_rows_, width() * ss, CV_8UC1, cv::Scalar(255));

    const int font = cv::FONT_HERSHEY_SIMPLEX;
    int base_baseline = 0;
    const cv::Size base = cv::getTextSize("Hg", font, 1.0, 1, &base_baseline);
    const double scale = 0.7 * line_px * ss / (base.height + base_baseline);
    const int thickness = std::max(1, static_cast<int>(std::lround(scale * 1.6)));
    const int margin = static_cast<int>(std::lround(0.04 * width() * ss));
    static const std::array<const char*, 32> words{
        "temporal", "resolution", "multiplexing", "the",     "frame",  "display", "of",      "and",
        "refresh",  "pixels",     "motion",       "a",       "is",     "eye",     "light",   "reduced",
        "full",     "sharp",      "panel",        "headset", "render", "to",      "with",    "between",
        "rate",     "in",         "blur",         "image",   "sees",   "every",   "quality", "pair"};
    for (int line = 0; line < lines; ++line) {
      if (line % 9 == 8) continue;  // paragraph break
      std::string text;
      for (int word = 0;; ++word) {
        const double u = scene_support::hash_unit(params().seed, 0x7465787475ULL, static_cast<std::uint64_t>(line),
                                                  static_cast<std::uint64_t>(word), 0);
        const std::string candidate = text + (text.empty() ? "" : " ") + words[static_cast<std::size_t>(u * words.size())];
        int baseline = 0;
        if (cv::getTextSize(candidate, font, scale, thickness, &baseline).width > width() * ss - 2 * margin) break;
        text = candidate;
      }
      const int baseline_y = static_cast<int>(std::lround((line + 0.78) * line_px * ss));
      cv::putText(ink, text, cv::Point(margin, baseline_y), font, scale, cv::Scalar(0), thickness, cv::LINE_8);
    }
    // Box filter across each pixel's ss columns (exact for integer factors), then prefix sums down the sub-rows.
    const double to_unit = 1.0 / (255.0 * ss);
    prefix_ = cv::Mat(sub_rows_ + 1, width(), CV_64FC1);
    prefix_.row(0).setTo(0.0);
    for (int k = 0; k < sub_rows_; ++k) {
      const std::uint8_t* src = ink.ptr<std::uint8_t>(k);
      const double* prev = prefix_.ptr<double>(k);
      double* dst = prefix_.ptr<double>(k + 1);
      for (int x = 0; x < width(); ++x) {
        int column_sum = 0;
        for (int i = 0; i < ss; ++i) column_sum += src[x * ss + i];
        dst[x] = prev[x] + column_sum * to_unit;
      }
    }
  }

  int sub_rows_ = 0;
  cv::Mat prefix_;  // (sub_rows + 1) x width: sum of the first k sub-rows of each column
};

// --- panorama (paper Exp. 1, Fig. 10): a horizontally repeating image panned from right to left -------
class PanoramaScene final : public AnalyticScene {
 public:
  explicit PanoramaScene(const SceneParams& p) : AnalyticScene("panorama", p) {
    const int quantum = scene_support::procedural_texture_period_quantum();
    const int period = (2 * p.width + quantum - 1) / quantum * quantum;  // seamless: a multiple of the lattice
    texture_ = texture_of_height(p, period, p.height);
  }
  cv::Mat linear_frame(std::int64_t t) override {
    return box_shift(texture_, speed() * seconds(t), 0.0, width(), height(), /*wrap_x=*/true);
  }
  Motion motion(std::int64_t) const override {
    Motion m;
    m.global_velocity_px_s = {-speed(), 0.0};
    return m;
  }

 private:
  double speed() const { return 0.25 * width(); }  // a quarter of the view width per second
  cv::Mat texture_;
};

// --- static: an image held still -----------------------------------------------------------------------
class StaticScene final : public AnalyticScene {
 public:
  explicit StaticScene(const SceneParams& p) : AnalyticScene("static", p) {
    if (!p.image_path.empty()) {
      image_ = scene_support::fit_cover(scene_support::load_linear_image(p.image_path), p.width, p.height);
    } else {
      image_ = box_shift(procedural_texture(p.width, p.height, p.seed, p.supersample), 0, 0, p.width, p.height, false);
    }
  }
  cv::Mat linear_frame(std::int64_t t) override {
    seconds(t);
    return image_.clone();
  }
  Motion motion(std::int64_t) const override { return {}; }

 private:
  cv::Mat image_;
};

// --- jitter and headturn: a still world seen by a rotating head ----------------------------------------
// The world is a texture on a plane in front of the viewer: at the rest pose the view is the texture's centre
// crop (so jitter at rest is the static scene), and a head at orientation R sees at pixel p the texture where the
// ray R K^-1 p meets the plane (trm/head_pose.hpp's pinhole view, kFovDeg across). Each pixel is the box filter of
// the piecewise-constant texture over its square moved to where the rotation puts its centre: a bilinear blend of
// four texels. (Exact for a translation; the rotation also scales the square, by less than 0.1 % for the jitter's
// rotations and up to 47 % at the view's edge at the head turn's largest yaw.) The texture is wide enough that no
// pose of the scene sees past it.
class HeadRotationScene : public AnalyticScene {
 public:
  HeadRotationScene(const std::string& name, const SceneParams& p, cv::Vec2d largest_angles_deg)
      : AnalyticScene(name, p), view_(PinholeView::of_fov(p.width, p.height, kFovDeg)) {
    margin_ = texture_margin(largest_angles_deg);
    const int tw = p.width + 2 * margin_.width, th = p.height + 2 * margin_.height;
    if (!p.image_path.empty()) {
      cv::Mat fitted = scene_support::fit_cover(scene_support::load_linear_image(p.image_path), tw, th);
      fitted.convertTo(texture_, CV_32FC3);
    } else {
      texture_ = procedural_texture(tw, th, p.seed, p.supersample);
    }
  }

  cv::Mat linear_frame(std::int64_t t) override {
    const Eigen::Matrix3d rotation = orientation(t).toRotationMatrix();
    const cv::Point2d c = view_.centre();
    const double f = view_.focal_px;
    cv::Mat frame(height(), width(), CV_64FC3);
    for (int y = 0; y < height(); ++y) {
      auto* row = frame.ptr<cv::Vec3d>(y);
      for (int x = 0; x < width(); ++x) {
        const Eigen::Vector3d d = rotation * view_.ray({static_cast<double>(x), static_cast<double>(y)});
        row[x] = bilinear_at(texture_, c.x + f * d.x() / d.z() + margin_.width, c.y + f * d.y() / d.z() + margin_.height);
      }
    }
    return frame;
  }

  std::optional<HeadView> head_view(std::int64_t t) const override { return HeadView{orientation(t), view_}; }

 protected:
  static constexpr double kFovDeg = 100.0;  // horizontal field of view of the view

  // Yaw (positive: the head turns right, content moves left) and pitch (positive: the head turns down), degrees.
  virtual cv::Vec2d angles_deg(std::int64_t t) const = 0;

  Eigen::Quaterniond orientation(std::int64_t t) const {
    const cv::Vec2d a = angles_deg(t) * (std::numbers::pi / 180.0);
    return Eigen::Quaterniond(Eigen::AngleAxisd(a[0], Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(-a[1], Eigen::Vector3d::UnitX()));
  }
  // Where the view's centre pixel lands on the texture's rest view (pixels) at frame t.
  cv::Point2d centre_on_texture(std::int64_t t) const {
    return reproject_pixel(view_.centre(), orientation(t), Eigen::Quaterniond::Identity(), view_);
  }
  const PinholeView& view() const { return view_; }

 private:
  // How far past the view's edges any pose within the largest angles looks, plus a texel for the bilinear blend.
  cv::Size texture_margin(cv::Vec2d largest_deg) const {
    double reach_x = 0.0, reach_y = 0.0;
    const double w = width() - 1.0, h = height() - 1.0;
    for (const double yaw : {-largest_deg[0], largest_deg[0]}) {
      for (const double pitch : {-largest_deg[1], largest_deg[1]}) {
        const double r = std::numbers::pi / 180.0;
        const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw * r, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(-pitch * r, Eigen::Vector3d::UnitX()));
        for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(w, 0), cv::Point2d(0, h), cv::Point2d(w, h),
                                    cv::Point2d(0.5 * w, 0), cv::Point2d(0.5 * w, h), cv::Point2d(0, 0.5 * h),
                                    cv::Point2d(w, 0.5 * h)}) {
          const cv::Point2d moved = reproject_pixel(p, q, Eigen::Quaterniond::Identity(), view_);
          reach_x = std::max(reach_x, std::abs(moved.x - p.x));
          reach_y = std::max(reach_y, std::abs(moved.y - p.y));
        }
      }
    }
    return {static_cast<int>(std::ceil(reach_x)) + 2, static_cast<int>(std::ceil(reach_y)) + 2};
  }

  PinholeView view_;
  cv::Size margin_;
  cv::Mat texture_;
};

// jitter (Kim et al., head-jittered aliasing): the still image under tiny involuntary head rotations, an
// Ornstein-Uhlenbeck process per axis, stationary standard deviation kSigmaDeg degrees, correlation time kTauS,
// sampled at the refresh rate and seeded.
class JitterScene final : public HeadRotationScene {
 public:
  explicit JitterScene(const SceneParams& p)
      : HeadRotationScene("jitter", p, cv::Vec2d::all(kLimitDeg)),
        noise_(scene_support::mix64(p.seed ^ 0x6a6974746572ULL)) {}

  Motion motion(std::int64_t t) const override {
    // Content moves opposite to where the view's centre lands on the texture; central difference in time.
    const std::int64_t a = t > 0 ? t - 1 : t;
    const std::int64_t b = t + 1;
    const cv::Point2d d = centre_on_texture(b) - centre_on_texture(a);
    Motion m;
    m.global_velocity_px_s = -cv::Vec2d(d.x, d.y) * (params().refresh_hz / static_cast<double>(b - a));
    return m;
  }

 private:
  static constexpr double kSigmaDeg = 0.05;  // involuntary head rotation while holding still
  static constexpr double kTauS = 0.25;
  static constexpr double kLimitDeg = 6.0 * kSigmaDeg;  // the walk is clamped here (never reached in practice)

  cv::Vec2d angles_deg(std::int64_t t) const override {
    seconds(t);
    while (static_cast<std::int64_t>(angles_.size()) <= t) {
      if (angles_.empty()) {
        angles_.push_back({kSigmaDeg * noise_.next(), kSigmaDeg * noise_.next()});  // start in the stationary state
        continue;
      }
      const double decay = std::exp(-1.0 / (params().refresh_hz * kTauS));
      const double kick = kSigmaDeg * std::sqrt(1.0 - decay * decay);
      const cv::Vec2d prev = angles_.back();
      angles_.push_back({prev[0] * decay + kick * noise_.next(), prev[1] * decay + kick * noise_.next()});
    }
    const cv::Vec2d a = angles_[static_cast<std::size_t>(t)];
    return {std::clamp(a[0], -kLimitDeg, kLimitDeg), std::clamp(a[1], -kLimitDeg, kLimitDeg)};
  }

  // The process is generated in order and memoised, so any access order gives the same frames.
  mutable scene_support::NormalStream noise_;
  mutable std::vector<cv::Vec2d> angles_;
};

// headturn: the same world under a deliberate head turn, yaw sweeping back and forth at kTurnDegS between
// -kTurnAmplitudeDeg and +kTurnAmplitudeDeg (starting at 0, turning right), no pitch.
class HeadTurnScene final : public HeadRotationScene {
 public:
  explicit HeadTurnScene(const SceneParams& p)
      : HeadRotationScene("headturn", p, cv::Vec2d(kTurnAmplitudeDeg, 0.0)) {}

  Motion motion(std::int64_t t) const override {
    // Per second of scene time: d/ds of f tan(yaw) at the centre, opposite in sign (content moves left).
    const double yaw = angles_deg(t)[0] * std::numbers::pi / 180.0;
    const double cos_yaw = std::cos(yaw);
    Motion m;
    m.global_velocity_px_s = {-yaw_rate_deg_s(t) * std::numbers::pi / 180.0 * view().focal_px / (cos_yaw * cos_yaw),
                              0.0};
    return m;
  }

 private:
  static constexpr double kTurnDegS = 10.0;  // a slow deliberate turn: within Kim et al.'s h_max, so it blends
  static constexpr double kTurnAmplitudeDeg = 8.0;

  // The sweep as a triangle wave of period 4 in units of the amplitude: phase in [0, 1) rises, [1, 3) falls back.
  double phase(std::int64_t t) const { return std::fmod(kTurnDegS * seconds(t) / kTurnAmplitudeDeg, 4.0); }
  double yaw_rate_deg_s(std::int64_t t) const {
    const double u = phase(t);
    return (u < 1.0 || u >= 3.0) ? kTurnDegS : -kTurnDegS;
  }
  cv::Vec2d angles_deg(std::int64_t t) const override {
    const double u = phase(t);
    const double tri = u < 1.0 ? u : (u < 3.0 ? 2.0 - u : u - 4.0);
    return {kTurnAmplitudeDeg * tri, 0.0};
  }
};

}  // namespace

std::unique_ptr<FrameSource> make_text(const SceneParams& p) { return std::make_unique<TextScene>(p); }
std::unique_ptr<FrameSource> make_panorama(const SceneParams& p) { return std::make_unique<PanoramaScene>(p); }
std::unique_ptr<FrameSource> make_static(const SceneParams& p) { return std::make_unique<StaticScene>(p); }
std::unique_ptr<FrameSource> make_jitter(const SceneParams& p) { return std::make_unique<JitterScene>(p); }
std::unique_ptr<FrameSource> make_headturn(const SceneParams& p) { return std::make_unique<HeadTurnScene>(p); }

}  // namespace trm::scenes
