#include "scenes/scene_support.hpp"
#include "scenes/scenes.hpp"

#include <functional>
#include <stdexcept>
#include <utility>

namespace trm {
namespace scenes {

AnalyticScene::AnalyticScene(std::string name, const SceneParams& params) : name_(std::move(name)), params_(params) {
  scene_support::validate_params(params_, name_);
}

double AnalyticScene::seconds(std::int64_t t) const { return scene_support::frame_time(t, params_.refresh_hz); }

}  // namespace scenes

namespace {
using Factory = std::unique_ptr<FrameSource> (*)(const SceneParams&);
const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> table{
      {"discs", scenes::make_discs},         {"text", scenes::make_text},       {"panorama", scenes::make_panorama},
      {"line", scenes::make_line},           {"zoneplate", scenes::make_zoneplate}, {"checker", scenes::make_checker},
      {"flash", scenes::make_flash},         {"static", scenes::make_static},   {"jitter", scenes::make_jitter},
      {"square", scenes::make_square},
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
    if (scene_name == name) return factory(params);
  }
  std::string valid;
  for (const auto& entry : registry()) valid += (valid.empty() ? "" : ", ") + entry.first;
  throw std::invalid_argument("unknown scene '" + name + "' (valid scenes: " + valid + ")");
}

}  // namespace trm
