// `reprojection`: the paper's Table 1 first row without the space warp (ASW-like, Sec. 6): every other frame
// rendered (TRM's full slots, so --phase and stereo off-phase apply alike); in the others the last rendered frame
// is rotated to the current head pose (trm/head_pose.hpp's reproject_view), its holes filled by edge replication.
// It runs GPU-side, as a compositor does, so every frame crosses the link: half the rendering, nothing saved on the
// link. Content that moves in the world (not by the head's rotation) is not followed: it judders as at half rate.
#include "method_support.hpp"

#include <map>

namespace trm::methods {

namespace {

class ReprojectionSender : public MethodSender {
 public:
  explicit ReprojectionSender(const MethodSetup& setup) : encoder_(setup.decoder.decoder.link), scene_(setup.source) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return view_meta_of(t, eye, Parity::Full, full, full, encoder_.config());
  }
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    Transmission out;
    auto last = rendered_.find(eye);
    const std::optional<HeadView> now = head_view(t);
    if (parity_of(t, eye, encoder_.config()) == Parity::Full || last == rendered_.end() ||
        last->second.frame.size() != linear.size()) {
      // A rendered frame; a stream that starts on a reprojected slot renders that one too.
      rendered_[eye] = Rendered{linear.clone(), now};
      out.frame = encoder_.encode_as(Parity::Full, linear, t, eye);
      out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());
      return out;
    }
    const Rendered& from = last->second;
    // Without head poses the head is still: the frame is shown again as it was.
    const cv::Mat shown = from.pose && now ? reproject_view(from.frame, from.pose->orientation, now->orientation,
                                                            now->projection)
                                           : from.frame;
    out.frame = encoder_.encode_as(Parity::Full, shown, t, eye);
    out.pixels_rendered = 0;
    return out;
  }

 private:
  struct Rendered {
    cv::Mat frame;                 // linear light, as rendered
    std::optional<HeadView> pose;  // the head pose it was rendered for
  };
  std::optional<HeadView> head_view(std::int64_t t) const { return scene_ ? scene_->head_view(t) : std::nullopt; }

  TrmEncoder encoder_;
  const FrameSource* scene_;
  std::map<int, Rendered> rendered_;  // per eye: the last rendered frame
};

}  // namespace

DisplayMethod reprojection_method() {
  DisplayMethod m;
  m.name = "reprojection";
  m.summary = "every other frame rendered, the last one rotated to the current head pose GPU-side (ASW-like)";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    return std::make_unique<ReprojectionSender>(setup);
  };
  m.make_display = [](const MethodSetup& setup) {
    return plain_frame_display(setup.decoder.decoder, Between::Nothing);
  };
  return m;
}

}  // namespace trm::methods
