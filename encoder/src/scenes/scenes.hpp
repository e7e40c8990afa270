// The analytic scenes (private to the encoder module); make_scene() in registry.cpp dispatches to these.
#pragma once

#include "trm/scene.hpp"

#include <memory>
#include <string>

namespace trm::scenes {

// Common plumbing: validated parameters, name, size, endless frame count, time of a frame.
class AnalyticScene : public FrameSource {
 public:
  AnalyticScene(std::string name, const SceneParams& params);
  std::string name() const override { return name_; }
  int width() const override { return params_.width; }
  int height() const override { return params_.height; }
  std::optional<std::int64_t> frame_count() const override { return std::nullopt; }

 protected:
  double seconds(std::int64_t t) const;
  const SceneParams& params() const { return params_; }

 private:
  std::string name_;
  SceneParams params_;
};

std::unique_ptr<FrameSource> make_discs(const SceneParams& params);
std::unique_ptr<FrameSource> make_line(const SceneParams& params);
std::unique_ptr<FrameSource> make_zoneplate(const SceneParams& params);
std::unique_ptr<FrameSource> make_checker(const SceneParams& params);
std::unique_ptr<FrameSource> make_flash(const SceneParams& params);
std::unique_ptr<FrameSource> make_text(const SceneParams& params);
std::unique_ptr<FrameSource> make_panorama(const SceneParams& params);
std::unique_ptr<FrameSource> make_static(const SceneParams& params);
std::unique_ptr<FrameSource> make_jitter(const SceneParams& params);
std::unique_ptr<FrameSource> make_headturn(const SceneParams& params);
std::unique_ptr<FrameSource> make_square(const SceneParams& params);

}  // namespace trm::scenes
