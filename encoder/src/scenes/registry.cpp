#include "scenes/scene_support.hpp"
#include "scenes/scenes.hpp"

#include <cmath>
#include <functional>
#include <stdexcept>
#include <utility>

namespace trm {
namespace scenes {

AnalyticScene::AnalyticScene(std::string name, const SceneParams& params) : name_(std::move(name)), params_(params) {
  scene_support::validate_params(params_, name_);
}

double AnalyticScene::seconds(std::int64_t t) const {
  return scene_support::frame_time(t, params_.refresh_hz) * params_.motion_scale;
}

}  // namespace scenes

namespace {

// Scenes time themselves by AnalyticScene::seconds, which applies motion_scale to where content is; this
// applies it to the velocities they report, which are per second of scene time.
class ScaledMotion final : public FrameSource {
 public:
  ScaledMotion(std::unique_ptr<FrameSource> scene, double scale) : scene_(std::move(scene)), scale_(scale) {}
  std::string name() const override { return scene_->name(); }
  int width() const override { return scene_->width(); }
  int height() const override { return scene_->height(); }
  std::optional<std::int64_t> frame_count() const override { return scene_->frame_count(); }
  cv::Mat linear_frame(std::int64_t t) override { return scene_->linear_frame(t); }
  std::optional<HeadView> head_view(std::int64_t t) const override { return scene_->head_view(t); }
  Motion motion(std::int64_t t) const override {
    Motion m = scene_->motion(t);
    m.global_velocity_px_s *= scale_;
    for (MotionObject& object : m.objects) object.velocity_px_s *= scale_;
    return m;
  }

 private:
  std::unique_ptr<FrameSource> scene_;
  double scale_;
};

// The scenes whose motion is not a function of scene time.
bool motion_is_timeless(const std::string& name) {
  return name == "static" || name == "flash" || name == "checker" || name == "jitter";
}

using Factory = std::unique_ptr<FrameSource> (*)(const SceneParams&);
const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> table{
      {"discs", scenes::make_discs},         {"text", scenes::make_text},       {"panorama", scenes::make_panorama},
      {"line", scenes::make_line},           {"zoneplate", scenes::make_zoneplate}, {"checker", scenes::make_checker},
      {"flash", scenes::make_flash},         {"static", scenes::make_static},   {"jitter", scenes::make_jitter},
      {"headturn", scenes::make_headturn}, {"square", scenes::make_square},
  };
  return table;
}
}  // namespace

std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.push_back(entry.first);
  return names;
}

std::unique_ptr<FrameSource> make_scene(const std::string& name, const SceneParams& params) {
  for (const auto& [scene_name, factory] : registry()) {
    if (scene_name != name) continue;
    if (params.motion_scale == 1.0) return factory(params);
    if (!std::isfinite(params.motion_scale) || params.motion_scale < 0.0) {
      throw std::invalid_argument("scene '" + name + "': the motion scale must be finite and >= 0, got " +
                                  std::to_string(params.motion_scale));
    }
    if (motion_is_timeless(name)) {
      throw std::invalid_argument("scene '" + name + "' has no motion whose speed can be set (its motion is not "
                                  "a function of time)");
    }
    return std::make_unique<ScaledMotion>(factory(params), params.motion_scale);
  }
  std::string valid;
  for (const auto& entry : registry()) valid += (valid.empty() ? "" : ", ") + entry.first;
  throw std::invalid_argument("unknown scene '" + name + "' (valid scenes: " + valid + ")");
}

}  // namespace trm
