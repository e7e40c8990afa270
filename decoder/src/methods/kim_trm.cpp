// `kim-trm`: Kim et al.'s temporal antialiasing GPU-side, then TRM (both target the same headset): each frame is
// blended as `kim` blends it, and the blended frame is what TRM's encoder sends (full and reduced frames
// alternating) and the TRM decoder of --impl shows.
#include "method_support.hpp"

#include "trm/kim_taa.hpp"

namespace trm::methods {

namespace {

class KimTrmSender : public MethodSender {
 public:
  explicit KimTrmSender(const MethodSetup& setup)
      : encoder_(setup.decoder.decoder.link),
        blend_(parse_kim_parameters(setup.option), setup.scene.refresh_hz, setup.source) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return trm_view_meta(t, eye, full, encoder_.config());
  }
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    Transmission out;
    out.frame = encoder_.encode(blend_.blend(linear, t, eye), t, eye);
    out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());  // as `trm` counts them
    return out;
  }

 private:
  TrmEncoder encoder_;
  KimBlend blend_;
};

}  // namespace

DisplayMethod kim_trm_method() {
  DisplayMethod m;
  m.name = "kim-trm";
  m.summary = "Kim et al. TAA GPU-side, then TRM: the blended frames sent as TRM's full and reduced frames";
  m.option_help = kKimOptionHelp;
  m.fixed_point = true;
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    return std::make_unique<KimTrmSender>(setup);
  };
  m.make_display = [](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    return std::make_unique<TrmFrameDisplay>(setup.impl, setup.decoder);
  };
  return m;
}

}  // namespace trm::methods
