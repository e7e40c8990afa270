// The building blocks of the `didyk` display method (decoder/src/methods/didyk.cpp): Didyk et al. 2010,
// "Perceptually-motivated real-time temporal upsampling of 3D content for high-refresh-rate displays"
// (seeds/001_2fec936d1875b300.txt, Secs. 5-6). Every N-th frame is rendered; the N - 1 frames after it are the
// rendered frame's blurred layer warped along the scene's motion on a grid snapped to the motion's discontinuities,
// and the rendered frame carries the high frequencies the blurred frames lack, N times over (gamma-correct).
#pragma once

#include "trm/pursuit.hpp"
#include "trm/scene.hpp"
#include "trm/transfer.hpp"

#include <opencv2/core.hpp>

#include <vector>

namespace trm::didyk {

// N, the frames per rendered frame: 3 turns 40 Hz rendering into 120 Hz (the paper's experiments).
inline constexpr int kDefaultUpsampling = 3;
inline constexpr int kMaxUpsampling = 8;
// Grid vertices are this many pixels apart, and each searches the non-overlapping square of this side around its
// regular position for the motion discontinuity to snap to (Sec. 6: "typically 8x8").
inline constexpr int kGridSpacing = 8;
// Sec. 6: tracking is assumed perfect up to 70 deg/s and lost from 90 deg/s (a cubic smooth step between),
// around Daly's 80 deg/s limit of smooth pursuit, the eye model's kPursuitMaxVelocity.
inline constexpr double kTrackingBandHalfWidthDegS = 10.0;
inline constexpr double kFullTrackingUpToDegS = kPursuitMaxVelocity - kTrackingBandHalfWidthDegS;
inline constexpr double kNoTrackingFromDegS = kPursuitMaxVelocity + kTrackingBandHalfWidthDegS;
// Sec. 5, selective blur: where the grid distorts (vertices of one triangle moving apart or together by this many
// pixels by the last in-between frame) the warped content is unreliable and the region stays blurred in every
// frame; a smooth step from the first figure (no extra blur) to the second (fully blurred).
inline constexpr double kDistortionBlurFromPx = 0.5;
inline constexpr double kDistortionBlurFullPx = 2.0;

// The cubic smooth step: 0 at or below `from`, 1 at or above `to` (from < to), zero slope at both ends.
double smooth_step(double x, double from, double to);

// Sec. 6: the fraction f of a motion at `speed_deg_s` (any sign) the eye tracks, hence the fraction of it the
// in-between frames follow: 1 up to kFullTrackingUpToDegS, 0 from kNoTrackingFromDegS.
double tracked_fraction(double speed_deg_s);

// One pixel of one channel in linear light, split between the rendered frame and the N - 1 in-between frames
// (Sec. 5, "Gamma correction" and "Selective blur"): in range, rendered = N original - (N - 1) low and between =
// low, which is N (H + L)^gamma = (L + Ĥ)^gamma + (N - 1) L^gamma in display values. Where that leaves [0, 1] the
// rendered frame is clipped and what it could not show moves into the in-between frames (so a pixel darker than its
// blur keeps its original in every frame when it is black): rendered + (N - 1) between = N original still, both in
// [0, 1]. original, low in [0, 1]; n >= 2.
struct PixelSplit {
  double rendered = 0.0;
  double between = 0.0;
};
PixelSplit split_pixel(double original, double low, int n);

// The paper's detail layer Ĥ in display values encoded by `transfer`: for the original H + L and its low-pass L,
// the value the rendered frame adds to L, from split_pixel (with a gamma transfer x^(1/gamma) it is
// (N (H + L)^gamma - (N - 1) L^gamma)^(1/gamma) - L while that is displayable).
double compensated_detail(double high, double low, int n, Transfer transfer);

// The scene's motion rasterised per pixel (what the paper rasterises from the vertices' two positions): the
// displacement per frame of the content at each pixel and its layer, for occlusions.
struct MotionField {
  cv::Mat step;   // CV_64FC2, pixels per frame: an object's velocity where a pixel centre lies in its bounds, else the
                  // global velocity, over the refresh rate
  cv::Mat layer;  // CV_32SC1: 0 background, i + 1 object i (later objects in front, as the scenes draw them)
};
// Throws std::invalid_argument for an empty size or a refresh rate that is not finite and > 0.
MotionField rasterise_motion(const Motion& motion, cv::Size size, double refresh_hz);

// A vertex of the morphing grid: where it sits in the rendered frame (pixel centres at integer coordinates), its
// displacement per frame and the layer of its pixel.
struct GridVertex {
  cv::Point2d at;
  cv::Vec2d step;
  int layer = 0;
};
struct Grid {
  int columns = 0;
  int rows = 0;
  cv::Size frame;
  std::vector<GridVertex> vertices;  // row-major, columns x rows
  const GridVertex& operator()(int column, int row) const {
    return vertices[static_cast<std::size_t>(row) * static_cast<std::size_t>(columns) +
                    static_cast<std::size_t>(column)];
  }
};

// Secs. 5-6: a regular grid of `spacing` pixels (last row and column on the frame's edge) whose inner vertices snap
// to the largest motion discontinuity (step or layer change to a neighbour behind) within their own spacing x spacing
// square, the nearest one on ties; vertices on the frame's border stay. No discontinuity: the vertex stays.
Grid snapped_grid(const MotionField& field, int spacing = kGridSpacing);

// Sec. 6's limited tracking: every vertex's step scaled by tracked_fraction of its speed (pixels per frame times
// refresh_hz over pixels_per_degree).
void damp_untrackable(Grid& grid, double refresh_hz, double pixels_per_degree);

// The frame `frames` frame steps after the rendered one: `source` (CV_64F, any channels, the grid's frame size)
// warped piecewise linearly by the grid's triangles moved by frames x step, occlusions resolved by layer (a
// triangle is in its vertices' rearmost layer, so the triangles stretched over a disocclusion lose to whole
// objects), sampled bilinearly in double precision with replicated borders. A pixel no triangle covers keeps its
// source value.
cv::Mat morph(const cv::Mat& source, const Grid& grid, double frames);

// Sec. 5: the blur strength in [0, 1] per pixel of the rendered frame, from the distortion of the triangles over
// it by the last in-between frame (`frames` steps): smooth_step(distortion, kDistortionBlurFromPx,
// kDistortionBlurFullPx), the least of the triangles sharing a pixel. CV_64FC1.
cv::Mat distortion_blur(const Grid& grid, double frames);

}  // namespace trm::didyk
