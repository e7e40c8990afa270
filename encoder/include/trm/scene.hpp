// Frame sources: analytic scenes (anti-aliased by supersampling, each knowing its own motion)
// and real inputs (image sequences, video files).
#pragma once

#include "trm/head_pose.hpp"

#include <opencv2/core.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace trm {

struct SceneParams {
  int width = 1080;            // full-resolution view size
  int height = 1200;
  double refresh_hz = 90.0;
  std::uint64_t seed = 1;      // for scenes with randomness (jitter, procedural texture)
  std::string image_path;      // panorama / static: optional image to use instead of the procedural texture
  int supersample = 4;         // samples per axis per pixel for analytic anti-aliasing
  // Every motion of the scene runs this many times as fast (scene time = frame time x motion_scale; velocities
  // scale alike), so a comparison can set its target's speed. Finite and >= 0 (0: the scene frozen at its first
  // frame); scenes whose motion is not a function of time (static, checker, flash, jitter's random head motion) accept
  // only 1.
  double motion_scale = 1.0;
};

// Motion of the content at one frame, in full-resolution pixels per second, for the eye model:
// a global velocity (panning, jitter) or per-object velocities with their bounding boxes.
struct MotionObject {
  cv::Rect2d bounds;           // pixels, at this frame
  cv::Vec2d velocity_px_s;
};
struct Motion {
  cv::Vec2d global_velocity_px_s{0.0, 0.0};
  std::vector<MotionObject> objects;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::string name() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;
  // Number of frames available, or nullopt for an endless analytic scene.
  virtual std::optional<std::int64_t> frame_count() const = 0;
  // Linear-light RGB frame t (CV_64FC3, values in [0, 1]); throws std::runtime_error on a read failure
  // and std::invalid_argument on NaN/Inf/negative/out-of-range content.
  virtual cv::Mat linear_frame(std::int64_t t) = 0;
  virtual Motion motion(std::int64_t t) const = 0;
  // The head pose the view of frame t is rendered for, for the scenes whose motion is the head rotating (jitter,
  // headturn): there the world is still and the head's rotation is all that moves it on the panel (which motion()
  // reports as well). nullopt for the others: what moves in them moves in the world.
  virtual std::optional<HeadView> head_view(std::int64_t) const { return std::nullopt; }
};

// Names: discs, text, panorama, line, zoneplate, checker, flash, static, jitter, headturn, square.
std::vector<std::string> scene_names();
// Throws std::invalid_argument naming the valid scenes when name is unknown.
std::unique_ptr<FrameSource> make_scene(const std::string& name, const SceneParams& params);

// The supplement's stimulus (§1.1): a square moving horizontally at a constant speed over a uniform background,
// the two linear luminances equidistant from half the display's, 0.5 (1 + c) and 0.5 (1 - c) for Michelson contrast
// c, so that neither the compensated frame's overshoot nor its undershoot reaches the display's range first. The
// square is vertically centred and wraps around horizontally (period: view width + side). Every pixel is the exact
// box-filter average of the continuous scene. "square" in make_scene is this with the defaults below.
struct MovingSquare {
  std::optional<double> side_px;        // default: a quarter of the smaller view side
  std::optional<double> speed_px_s;     // default: half a view width per second (negative: toward -x)
  std::optional<double> start_left_px;  // the left edge at t = 0; default: the square centred in the view
  double contrast = 0.2;                // Michelson contrast, in [0, 1]; the square is the brighter
};
// Throws std::invalid_argument naming the field for a side that is not finite and > 0, a speed or start that is not
// finite, or a contrast outside [0, 1]; and as make_scene for bad params.
std::unique_ptr<FrameSource> make_moving_square(const SceneParams& params, const MovingSquare& square);

// Image sequence: a glob such as 'DIR/frame_*.png' (sorted by name), 8- or 16-bit PNG (or any format
// OpenCV reads), sRGB-encoded. Validates up front: at least one file, all readable images, same size.
// Throws std::runtime_error with a message naming the offending file.
std::unique_ptr<FrameSource> open_image_sequence(const std::string& pattern);
// Video file through OpenCV (sRGB-encoded 8-bit frames).
std::unique_ptr<FrameSource> open_video(const std::string& path);

}  // namespace trm
