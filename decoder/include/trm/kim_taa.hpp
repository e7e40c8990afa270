// Kim et al.'s head-movement based temporal antialiasing (002_3cb3bea4249c5cbe.txt Sec. 4), the GPU-side blend of
// the `kim` and `kim-trm` display methods. Each frame k blends the current render with the previous output,
// reprojected part of the way back along the head's rotation:
//   s_i    = P slerp(V_{k-1}, V_k, d_i) V_k^-1 v_p                              (Eq. 1, interpolated reprojection)
//   c_past = sum_i W(d_i) c_{k-1}(s_i)                                          (Eq. 2)
//   c_k    = (1 - A(h)) c_past + A(h) C_k(p)                                    (Eq. 3)
//   A(h)   = (1 - w'_min) (-(cos(pi h / h_max) - 1) / 2)^2 + w'_min, 1 above h_max   (Eq. 4)
//   w'_min = w_min - (w_min - w_lb) c_diff                                      (Eq. 5, per pixel)
// h is the head's angular speed (deg/s) between frames k-1 and k; c_diff the colour change |C_k(p) - c_past| of the
// pixel (Euclidean over sRGB-encoded R, G, B in [0, 1], over sqrt(3), so 1 is black against white). With n samples,
// d_i = d (i + 1) / n and W(d_i) = d_i / sum_j d_j (the more recent, the heavier, summing to 1; n = 1: d_0 = d).
// Blending is in linear light. Regions the scene moves in the world (not by the head's rotation) are not blended
// (Sec. 4.4's dynamic map, drawn from the scene's own motion).
#pragma once

#include "trm/head_pose.hpp"
#include "trm/scene.hpp"

#include <map>
#include <optional>
#include <string>

namespace trm {

struct KimParameters {
  double d = 2.0 / 3.0;      // closeness of the past sample to the current head pose (0: the full inverse)
  int n = 1;                 // past samples per pixel
  double h_max_deg_s = 25.0; // head speed from which nothing is blended
  double w_min = 0.3;        // weight of the current frame with the head still
  double w_lb = 0.1;         // its lower bound where the colour changes most

  // Throws std::invalid_argument naming the field unless d in [0, 1], n in [1, kMaxSamples], h_max finite and > 0,
  // 0 <= w_lb <= w_min <= 1.
  void validate() const;
  static constexpr int kMaxSamples = 8;
};

// "d=0.5,n=2,hmax=25,wmin=0.3,wlb=0.1" (any subset, any order; "" for the defaults), validated. Throws
// std::invalid_argument naming the unknown key or the bad value.
KimParameters parse_kim_parameters(const std::string& option);
// The help text of that option, for `trm methods`.
extern const char* const kKimOptionHelp;

// Eq. 4 with Eq. 5's w'_min: the weight of the current frame at head speed h (deg/s).
double kim_current_weight(double head_speed_deg_s, double w_min, double h_max_deg_s);
// Eq. 5.
double kim_local_min_weight(double colour_change, double w_min, double w_lb);

// The blend of one run, per eye. `scene` (may be null: a recorded input) gives the head poses (none: the head is
// held still, at the identity) and the world's motion for the dynamic map.
class KimBlend {
 public:
  KimBlend(const KimParameters& parameters, double refresh_hz, const FrameSource* scene);
  // c_k for the render `current` (CV_64FC3, linear) of frame t of `eye`. The first frame of an eye, or one that does
  // not follow its previous frame, is the render itself.
  cv::Mat blend(const cv::Mat& current, std::int64_t t, int eye);
  const KimParameters& parameters() const { return parameters_; }

 private:
  struct History {
    std::int64_t t = -1;
    cv::Mat output;
    Eigen::Quaterniond orientation;
  };
  Eigen::Quaterniond orientation(std::int64_t t) const;
  PinholeView projection(cv::Size size) const;
  cv::Mat dynamic_mask(std::int64_t t, cv::Size size) const;

  KimParameters parameters_;
  double refresh_hz_;
  const FrameSource* scene_;
  std::map<int, History> history_;
};

}  // namespace trm
