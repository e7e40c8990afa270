#include "sweep_perceived.hpp"

#include "trm/metrics.hpp"
#include "trm/pursuit.hpp"
#include "trm/transfer.hpp"
#include "trm/visual_difference.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace trm::cli {

namespace {

// The liquid crystal's state after showing `levels` for a frame from (`state`, `rate`), in place; `rate` is the
// second-order LC's (empty for the first-order models).
void advance_state(cv::Mat& state, cv::Mat& rate, const cv::Mat& levels, const PanelLight& light) {
  auto* s = state.ptr<double>(0);
  auto* r = rate.empty() ? nullptr : rate.ptr<double>(0);
  const auto* l = levels.ptr<double>(0);
  const std::size_t samples = levels.total() * static_cast<std::size_t>(levels.channels());
  for (std::size_t i = 0; i < samples; ++i) {
    if (r) {
      const LcMotion next = light.end_state(LcMotion{s[i], r[i]}, l[i]);
      s[i] = next.level;
      r[i] = next.rate_per_s;
    } else {
      s[i] = light.end_state(s[i], l[i]);
    }
  }
}

}  // namespace

EyeSetup eye_setup(const Panel& panel, int output_bits, double refresh_hz, double target_velocity_px_s, int scan_line,
                   int rows) {
  EyeSetup setup{panel, output_bits, panel_light(panel, refresh_hz), viewer_preset("vive")};
  setup.target_velocity_deg_s = target_velocity_px_s / setup.viewer.pixels_per_degree;
  setup.eye_velocity_deg_s = Gaze::pursuit(setup.target_velocity_deg_s).eye_velocity_deg_s;
  setup.retinal_velocity_deg_s = retinal_velocity_deg_s(setup.target_velocity_deg_s);
  setup.scan_line = scan_line;
  setup.rows = rows;
  return setup;
}

PerceivedSequence perceive(const std::vector<ShownFrame>& frames, const EyeSetup& setup, int substeps) {
  if (frames.empty()) throw std::invalid_argument("perceive: `frames` is empty");
  PerceivedSequence seen;
  seen.substeps = substeps;
  std::vector<cv::Mat> levels;
  std::vector<cv::Mat> scan_line;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i > 0 && frames[i].t <= frames[i - 1].t) throw std::invalid_argument("perceive: `frames` not in time order");
    levels.push_back(steady_levels(setup.panel, setup.output_bits, frames[i].drive_codes));
    scan_line.push_back(luma(levels.back().row(setup.scan_line)));
  }
  const double period = setup.light.frame_period_s();
  RetinaOptions retina;
  retina.substeps = substeps;
  // The LC state each pair starts from: the frames before it shown in turn (settled at the first frame).
  // (A second-order LC starts at rest and carries its rate along.)
  cv::Mat state, rate;
  if (setup.light.has_lc_state()) state = levels.front().clone();
  if (setup.light.lc_second_order()) rate = cv::Mat::zeros(levels.front().size(), levels.front().type());
  std::size_t advanced = 0;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    if (frames[i].t % 2 != 0 || frames[i + 1].t != frames[i].t + 1) continue;
    if (!state.empty()) {
      for (; advanced < i; ++advanced) advance_state(state, rate, levels[advanced], setup.light);
    }
    // The retinal grid lies on the screen's at the pair's start, for every sequence alike.
    retina.origin_s = static_cast<double>(frames[i].t) * period;
    seen.pairs.push_back(retinal_image({levels[i], levels[i + 1]}, setup.light, setup.viewer,
                                       setup.eye_velocity_deg_s, retina, advanced > 0 ? state : cv::Mat(),
                                       advanced > 0 ? rate : cv::Mat()));
  }
  cv::Mat lines;
  cv::vconcat(scan_line, lines);
  RetinaOptions line = retina;
  line.origin_s = static_cast<double>(frames.front().t) * period;
  line.row = setup.scan_line;
  line.rows = setup.rows;
  seen.xt = target_frame_xt(lines, setup.light, setup.viewer, Gaze::pursuit(setup.target_velocity_deg_s), line);
  return seen;
}

PerceivedError perceived_error(const PerceivedSequence& seen, const PerceivedSequence& reference,
                               const EyeSetup& setup) {
  if (seen.pairs.size() != reference.pairs.size() || seen.substeps < 1 || reference.substeps % seen.substeps != 0 ||
      seen.xt.cols != reference.xt.cols ||
      seen.xt.rows / seen.substeps != reference.xt.rows / reference.substeps) {
    throw std::invalid_argument("perceived_error: `seen` and `reference` are not of the same frames, or the "
                                "reference's sub-steps are no multiple of seen's");
  }
  PerceivedError error;
  if (seen.pairs.empty()) {
    error.psnr_db = std::numeric_limits<double>::infinity();
  } else {
    cv::Mat a, b;
    cv::vconcat(seen.pairs, a);
    cv::vconcat(reference.pairs, b);
    error.psnr_db = psnr_srgb(a, b);
  }
  // Each reference row is the mean light over its sub-step: the mean of `group` of them is the mean over seen's.
  const int group = reference.substeps / seen.substeps;
  cv::Mat coarse(seen.xt.size(), CV_64FC1, cv::Scalar(0.0));
  for (int r = 0; r < reference.xt.rows; ++r) coarse.row(r / group) += reference.xt.row(r) / group;
  error.visual_difference =
      visual_difference_energy(seen.xt, coarse, setup.viewer.pixels_per_degree,
                               xt_samples_per_second(setup.light, seen.substeps), setup.retinal_velocity_deg_s);
  return error;
}

}  // namespace trm::cli
