// `didyk`: perceptually motivated temporal upsampling (Didyk et al. 2010, Secs. 5-6; the building blocks in
// trm/didyk.hpp). The GPU side renders every N-th frame, shows it with its high frequencies boosted N times
// (gamma-correct, selective blur at the range limits and where the grid distorts), and synthesises the N - 1 frames
// after it from the rendered frame's blurred layer, warped along the scene's own motion on a snapped grid, less far
// where the eye cannot follow. Every slot carries a whole frame: the saving is in rendering, none on the link.
// "didyk:N-hold" is the native N-times-slower rendering the paper compares with (each rendered frame shown N times,
// nothing sent between).
#include "trm/didyk.hpp"

#include "method_support.hpp"

#include "trm/resample.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace trm::didyk {

double smooth_step(double x, double from, double to) {
  const double u = std::clamp((x - from) / (to - from), 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

double tracked_fraction(double speed_deg_s) {
  return 1.0 - smooth_step(std::abs(speed_deg_s), kFullTrackingUpToDegS, kNoTrackingFromDegS);
}

PixelSplit split_pixel(double original, double low, int n) {
  const double total = n * original;  // the light the n frames must emit together
  const double rendered = total - (n - 1) * low;
  if (rendered > 1.0) return {1.0, (total - 1.0) / (n - 1)};  // <= 1 since original <= 1
  if (rendered < 0.0) return {0.0, total / (n - 1)};          // < low <= 1
  return {rendered, low};
}

double compensated_detail(double high, double low, int n, Transfer transfer) {
  const double rendered = split_pixel(to_linear(high + low, transfer), to_linear(low, transfer), n).rendered;
  return to_encoded(rendered, transfer) - low;
}

MotionField rasterise_motion(const Motion& motion, cv::Size size, double refresh_hz) {
  if (size.width < 1 || size.height < 1) throw std::invalid_argument("didyk: motion field of an empty frame");
  if (!(std::isfinite(refresh_hz) && refresh_hz > 0.0)) {
    throw std::invalid_argument("didyk: the refresh rate must be finite and > 0");
  }
  MotionField field;
  field.step = cv::Mat(size, CV_64FC2, cv::Scalar(motion.global_velocity_px_s[0] / refresh_hz,
                                                  motion.global_velocity_px_s[1] / refresh_hz));
  field.layer = cv::Mat::zeros(size, CV_32SC1);
  for (std::size_t i = 0; i < motion.objects.size(); ++i) {
    const MotionObject& object = motion.objects[i];
    const cv::Rect2d& b = object.bounds;
    // Pixel centres x + 0.5 in [b.x, b.x + b.width).
    const int x0 = std::max(0, static_cast<int>(std::ceil(b.x - 0.5)));
    const int x1 = std::min(size.width, static_cast<int>(std::ceil(b.x + b.width - 0.5)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(b.y - 0.5)));
    const int y1 = std::min(size.height, static_cast<int>(std::ceil(b.y + b.height - 0.5)));
    const cv::Vec2d step = object.velocity_px_s / refresh_hz;
    for (int y = y0; y < y1; ++y) {
      auto* s = field.step.ptr<cv::Vec2d>(y);
      auto* l = field.layer.ptr<int>(y);
      for (int x = x0; x < x1; ++x) {
        s[x] = step;
        l[x] = static_cast<int>(i) + 1;
      }
    }
  }
  return field;
}

namespace {

// Regular positions along one axis: 0, spacing, 2 spacing, ..., and the last pixel (at least two, so that a frame
// one pixel wide still has a cell, a degenerate one).
std::vector<int> regular_positions(int pixels, int spacing) {
  std::vector<int> out;
  for (int p = 0; p < pixels - 1; p += spacing) out.push_back(p);
  out.push_back(pixels - 1);
  if (out.size() < 2) out.push_back(pixels - 1);
  return out;
}

// How sharply the motion changes at p toward a neighbour at the same depth or behind it: the snapping target
// lies on the front side of a discontinuity, so that the vertex moves with the object that occludes.
double discontinuity(const MotionField& field, int x, int y) {
  const cv::Vec2d step = field.step.at<cv::Vec2d>(y, x);
  const int layer = field.layer.at<int>(y, x);
  double strongest = 0.0;
  constexpr std::array<std::array<int, 2>, 4> kNeighbours{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  for (const auto& [dx, dy] : kNeighbours) {
    const int qx = x + dx, qy = y + dy;
    if (qx < 0 || qy < 0 || qx >= field.step.cols || qy >= field.step.rows) continue;
    const int other = field.layer.at<int>(qy, qx);
    if (other > layer) continue;
    strongest = std::max(strongest, cv::norm(step - field.step.at<cv::Vec2d>(qy, qx)));
  }
  return strongest;
}

// Calls visit(x, y, triangle, barycentric) for every pixel centre inside each of the grid's triangles placed at
// `place(vertex)` (two per cell), the triangles in cell order.
template <typename Place, typename Visit>
void rasterise_triangles(const Grid& grid, Place place, Visit visit) {
  const int width = grid.frame.width, height = grid.frame.height;
  int triangle = 0;
  for (int j = 0; j + 1 < grid.rows; ++j) {
    for (int i = 0; i + 1 < grid.columns; ++i) {
      const std::array<std::array<const GridVertex*, 3>, 2> triangles{
          std::array<const GridVertex*, 3>{&grid(i, j), &grid(i + 1, j), &grid(i + 1, j + 1)},
          std::array<const GridVertex*, 3>{&grid(i, j), &grid(i + 1, j + 1), &grid(i, j + 1)}};
      for (const auto& corners : triangles) {
        const cv::Point2d a = place(*corners[0]), b = place(*corners[1]), c = place(*corners[2]);
        const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        const int index = triangle++;
        if (std::abs(area) < 1e-12) continue;
        constexpr double kEdgeTolerance = 1e-9;  // pixel centres on a shared edge belong to both triangles
        const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x, b.x, c.x}) - kEdgeTolerance)));
        const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.x, b.x, c.x}) + kEdgeTolerance)));
        const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y, b.y, c.y}) - kEdgeTolerance)));
        const int y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a.y, b.y, c.y}) + kEdgeTolerance)));
        for (int y = y0; y <= y1; ++y) {
          for (int x = x0; x <= x1; ++x) {
            const double wa = ((b.x - x) * (c.y - y) - (b.y - y) * (c.x - x)) / area;
            const double wb = ((c.x - x) * (a.y - y) - (c.y - y) * (a.x - x)) / area;
            const double wc = 1.0 - wa - wb;
            if (wa < -kEdgeTolerance || wb < -kEdgeTolerance || wc < -kEdgeTolerance) continue;
            visit(x, y, index, corners, cv::Vec3d(wa, wb, wc));
          }
        }
      }
    }
  }
}

// Bilinear sample of `source` at (x, y) (pixel centres at integers), replicated borders, every channel.
void sample_bilinear(const cv::Mat& source, double x, double y, double* out) {
  const int channels = source.channels();
  x = std::clamp(x, 0.0, source.cols - 1.0);
  y = std::clamp(y, 0.0, source.rows - 1.0);
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const int x1 = std::min(x0 + 1, source.cols - 1), y1 = std::min(y0 + 1, source.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const auto* r0 = source.ptr<double>(y0);
  const auto* r1 = source.ptr<double>(y1);
  for (int c = 0; c < channels; ++c) {
    const double top = r0[x0 * channels + c] * (1.0 - fx) + r0[x1 * channels + c] * fx;
    const double bottom = r1[x0 * channels + c] * (1.0 - fx) + r1[x1 * channels + c] * fx;
    out[c] = top * (1.0 - fy) + bottom * fy;
  }
}

}  // namespace

Grid snapped_grid(const MotionField& field, int spacing) {
  if (spacing < 1) throw std::invalid_argument("didyk: grid spacing must be >= 1");
  const int width = field.step.cols, height = field.step.rows;
  const std::vector<int> xs = regular_positions(width, spacing), ys = regular_positions(height, spacing);
  Grid grid;
  grid.columns = static_cast<int>(xs.size());
  grid.rows = static_cast<int>(ys.size());
  grid.frame = field.step.size();
  grid.vertices.reserve(xs.size() * ys.size());
  for (int j = 0; j < grid.rows; ++j) {
    for (int i = 0; i < grid.columns; ++i) {
      cv::Point at(xs[static_cast<std::size_t>(i)], ys[static_cast<std::size_t>(j)]);
      const bool border = i == 0 || j == 0 || i + 1 == grid.columns || j + 1 == grid.rows;
      if (!border) {
        // The vertex's own square, [p - spacing / 2, p + spacing / 2), inside the frame's inner pixels.
        const int half = spacing / 2;
        double best = 0.0;
        long best_distance = std::numeric_limits<long>::max();
        const cv::Point regular = at;
        for (int y = std::max(1, regular.y - half); y < std::min(height - 1, regular.y - half + spacing); ++y) {
          for (int x = std::max(1, regular.x - half); x < std::min(width - 1, regular.x - half + spacing); ++x) {
            const double strength = discontinuity(field, x, y);
            const long distance = static_cast<long>(x - regular.x) * (x - regular.x) +
                                  static_cast<long>(y - regular.y) * (y - regular.y);
            if (strength > best || (strength == best && strength > 0.0 && distance < best_distance)) {
              best = strength;
              best_distance = distance;
              at = cv::Point(x, y);
            }
          }
        }
      }
      grid.vertices.push_back({cv::Point2d(at), field.step.at<cv::Vec2d>(at), field.layer.at<int>(at)});
    }
  }
  return grid;
}

void damp_untrackable(Grid& grid, double refresh_hz, double pixels_per_degree) {
  if (!(std::isfinite(pixels_per_degree) && pixels_per_degree > 0.0)) {
    throw std::invalid_argument("didyk: pixels per degree must be finite and > 0");
  }
  for (GridVertex& v : grid.vertices) v.step *= tracked_fraction(cv::norm(v.step) * refresh_hz / pixels_per_degree);
}

cv::Mat morph(const cv::Mat& source, const Grid& grid, double frames) {
  if (source.depth() != CV_64F || source.size() != grid.frame) {
    throw std::invalid_argument("didyk: morph needs a CV_64F frame of the grid's size");
  }
  // Per destination pixel: where in the source it reads, and the layer of the triangle that wrote it.
  cv::Mat from(grid.frame, CV_64FC2);
  cv::Mat depth(grid.frame, CV_32SC1, cv::Scalar(-1));
  const auto moved = [frames](const GridVertex& v) {
    return v.at + cv::Point2d(frames * v.step[0], frames * v.step[1]);
  };
  rasterise_triangles(grid, moved, [&](int x, int y, int, const auto& corners, const cv::Vec3d& w) {
    const int layer = std::min({corners[0]->layer, corners[1]->layer, corners[2]->layer});
    int& written = depth.at<int>(y, x);
    if (layer <= written) return;  // behind (or level with) what is there: the first triangle of a layer stays
    written = layer;
    from.at<cv::Vec2d>(y, x) = cv::Vec2d(w[0] * corners[0]->at.x + w[1] * corners[1]->at.x + w[2] * corners[2]->at.x,
                                         w[0] * corners[0]->at.y + w[1] * corners[1]->at.y + w[2] * corners[2]->at.y);
  });
  cv::Mat out(source.size(), source.type());
  for (int y = 0; y < out.rows; ++y) {
    auto* row = out.ptr<double>(y);
    for (int x = 0; x < out.cols; ++x) {
      const bool covered = depth.at<int>(y, x) >= 0;
      const cv::Vec2d p = covered ? from.at<cv::Vec2d>(y, x) : cv::Vec2d(x, y);
      sample_bilinear(source, p[0], p[1], row + static_cast<std::ptrdiff_t>(x) * source.channels());
    }
  }
  return out;
}

cv::Mat distortion_blur(const Grid& grid, double frames) {
  cv::Mat strength(grid.frame, CV_64FC1, cv::Scalar(1.0));
  cv::Mat covered = cv::Mat::zeros(grid.frame, CV_8UC1);
  rasterise_triangles(grid, [](const GridVertex& v) { return v.at; },
                      [&](int x, int y, int, const auto& corners, const cv::Vec3d&) {
                        double distortion = 0.0;
                        for (int e = 0; e < 3; ++e) {
                          const GridVertex& a = *corners[static_cast<std::size_t>(e)];
                          const GridVertex& b = *corners[static_cast<std::size_t>((e + 1) % 3)];
                          distortion = std::max(distortion, frames * cv::norm(a.step - b.step));
                        }
                        const double s = smooth_step(distortion, kDistortionBlurFromPx, kDistortionBlurFullPx);
                        double& here = strength.at<double>(y, x);
                        here = covered.at<std::uint8_t>(y, x) ? std::min(here, s) : s;
                        covered.at<std::uint8_t>(y, x) = 1;
                      });
  strength.setTo(0.0, covered == 0);  // not covered (a frame one pixel wide or high): no grid, no distortion
  return strength;
}

}  // namespace trm::didyk

namespace trm::methods {

namespace {

struct DidykOptions {
  int upsampling = didyk::kDefaultUpsampling;
  bool hold = false;  // native rendering at refresh / N: each rendered frame shown N times
};

DidykOptions parse_didyk_option(const std::string& option) {
  DidykOptions out;
  const auto refuse = [&option] {
    return std::invalid_argument("method 'didyk': unknown option '" + option + "' (N from 2 to " +
                                 std::to_string(didyk::kMaxUpsampling) + ", 'hold', or 'N-hold')");
  };
  if (!option.empty() && option.back() == '-') throw refuse();
  std::size_t begin = 0;
  while (begin < option.size()) {
    // '-', not ',': a method name is one field of frames.csv and one item of `trm compare --methods`.
    const std::size_t dash = option.find('-', begin);
    const std::string part = option.substr(begin, dash == std::string::npos ? std::string::npos : dash - begin);
    if (part == "hold") {
      out.hold = true;
    } else if (part.size() == 1 && part[0] >= '2' && part[0] <= '0' + didyk::kMaxUpsampling) {
      out.upsampling = part[0] - '0';
    } else {
      throw refuse();
    }
    if (dash == std::string::npos) break;
    begin = dash + 1;
  }
  return out;
}

class DidykSender : public MethodSender {
 public:
  DidykSender(const MethodSetup& setup, DidykOptions options)
      : encoder_(setup.decoder.decoder.link), scene_(setup.scene), options_(options) {}

  bool sends(std::int64_t t, int) const override { return !options_.hold || rendered_slot(t); }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return view_meta_of(t, eye, Parity::Full, full, full, encoder_.config());
  }

  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    const auto state = eyes_.find(eye);
    if (rendered_slot(t) || state == eyes_.end() || options_.hold) return render(linear, t, eye);
    // An in-between frame: nothing rendered, the blurred layer warped (t - rendered) frames on.
    const Rendered& last = state->second;
    const cv::Mat warped = didyk::morph(last.between_encoded, last.grid, static_cast<double>(t - last.t));
    Transmission out;
    out.frame = encoder_.encode_as(Parity::Full, to_linear(warped, encoder_.config().transfer), t, eye);
    return out;
  }

 private:
  struct Rendered {
    std::int64_t t = 0;
    didyk::Grid grid;
    cv::Mat between_encoded;  // what the in-between frames warp: the blurred layer after the range shifts, encoded
  };

  bool rendered_slot(std::int64_t t) const { return t % options_.upsampling == 0; }

  Transmission render(const cv::Mat& linear, std::int64_t t, int eye) {
    const EncoderConfig& link = encoder_.config();
    Transmission out;
    out.pixels_rendered = static_cast<std::int64_t>(linear.total());
    const LinkFrame plain = encoder_.encode_as(Parity::Full, linear, t, eye);
    if (options_.hold) {
      out.frame = plain;
      return out;
    }
    // What the GPU rendered, as it resolved it (the link's codes), and its blur: the encoder's Gaussian (--sigma) at
    // full size, on encoded values as the paper blurs 8-bit RGB.
    const cv::Mat encoded = dequantise(plain.codes, link.bits);
    const cv::Mat low_encoded = downsample(encoded, encoded.cols, encoded.rows, link.effective_sigma());
    const cv::Mat original = to_linear(encoded, link.transfer);
    const cv::Mat low = to_linear(low_encoded, link.transfer);

    Rendered& state = eyes_[eye];
    state.t = t;
    const Motion motion = scene_.at ? scene_.at(t) : Motion{};
    state.grid = didyk::snapped_grid(didyk::rasterise_motion(motion, linear.size(), scene_.refresh_hz));
    didyk::damp_untrackable(state.grid, scene_.refresh_hz, scene_.pixels_per_degree);
    const int n = options_.upsampling;
    const cv::Mat blur_strength = didyk::distortion_blur(state.grid, n - 1.0);

    cv::Mat rendered(linear.size(), CV_64FC3), between(linear.size(), CV_64FC3);
    for (int y = 0; y < linear.rows; ++y) {
      const auto* i_row = original.ptr<cv::Vec3d>(y);
      const auto* l_row = low.ptr<cv::Vec3d>(y);
      const auto* s_row = blur_strength.ptr<double>(y);
      auto* r_row = rendered.ptr<cv::Vec3d>(y);
      auto* b_row = between.ptr<cv::Vec3d>(y);
      for (int x = 0; x < linear.cols; ++x) {
        for (int c = 0; c < 3; ++c) {
          // Where the grid distorts, the original blends toward its blur: less detail to boost, blurred in all frames.
          const double kept = i_row[x][c] + s_row[x] * (l_row[x][c] - i_row[x][c]);
          const didyk::PixelSplit split = didyk::split_pixel(kept, l_row[x][c], n);
          r_row[x][c] = split.rendered;
          b_row[x][c] = split.between;
        }
      }
    }
    state.between_encoded = to_encoded(between, link.transfer);
    out.frame = encoder_.encode_as(Parity::Full, rendered, t, eye);
    return out;
  }

  TrmEncoder encoder_;
  MethodSetup::SceneMotion scene_;
  DidykOptions options_;
  std::map<int, Rendered> eyes_;
};

}  // namespace

DisplayMethod didyk_method() {
  DisplayMethod m;
  m.name = "didyk";
  m.summary = "Didyk et al. 2010: every 3rd frame rendered, boosted; the others its blur warped along the scene's "
              "motion (33 % pixels rendered, 100 % sent)";
  m.option_help = "N (2..8, default 3: every N-th frame rendered), hold (native refresh/N: each rendered frame shown "
                  "N times, nothing sent between), or N-hold";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    return std::make_unique<DidykSender>(setup, parse_didyk_option(setup.option));
  };
  m.make_display = [](const MethodSetup& setup) {
    return plain_frame_display(setup.decoder.decoder,
                               parse_didyk_option(setup.option).hold ? Between::Repeat : Between::Nothing);
  };
  return m;
}

}  // namespace trm::methods
