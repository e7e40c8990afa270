// `kim`: Kim et al.'s head-movement based temporal antialiasing (002_3cb3bea4249c5cbe.txt Sec. 4, trm/kim_taa.hpp):
// every frame rendered at full resolution, blended GPU-side with the previous output reprojected part of the way
// back along the head's rotation, and sent whole. Nothing is saved; what it buys is less frame-to-frame change
// (head-jittered aliasing) at the cost of blur while the head moves slowly.
#include "method_support.hpp"

#include "trm/kim_taa.hpp"

namespace trm::methods {

namespace {

class KimSender : public MethodSender {
 public:
  explicit KimSender(const MethodSetup& setup)
      : encoder_(setup.decoder.decoder.link),
        blend_(parse_kim_parameters(setup.option), setup.scene.refresh_hz, setup.source) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return view_meta_of(t, eye, Parity::Full, full, full, encoder_.config());
  }
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    Transmission out;
    out.frame = encoder_.encode_as(Parity::Full, blend_.blend(linear, t, eye), t, eye);
    out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());
    return out;
  }

 private:
  TrmEncoder encoder_;
  KimBlend blend_;
};

}  // namespace

DisplayMethod kim_method() {
  DisplayMethod m;
  m.name = "kim";
  m.summary = "Kim et al. head-movement TAA: every frame rendered, blended with the reprojected previous output";
  m.option_help = kKimOptionHelp;
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    return std::make_unique<KimSender>(setup);
  };
  m.make_display = [](const MethodSetup& setup) {
    return plain_frame_display(setup.decoder.decoder, Between::Nothing);
  };
  return m;
}

}  // namespace trm::methods
