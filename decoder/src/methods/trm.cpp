// `trm`: Temporal Resolution Multiplexing (the paper, DESIGN §4): full and reduced frames alternate, the headset
// upsamples, compensates and keeps the residual out of moving content. The only method with the fixed-point
// hardware model of its whole headset side.
#include "method_support.hpp"

namespace trm::methods {

namespace {

class TrmSender : public MethodSender {
 public:
  explicit TrmSender(const EncoderConfig& link) : encoder_(link) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return trm_view_meta(t, eye, full, encoder_.config());
  }
  // The GPU renders a reduced frame at the reduced size: its cost is the view's size.
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    Transmission out;
    out.frame = encoder_.encode(linear, t, eye);
    out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());
    return out;
  }

 private:
  TrmEncoder encoder_;
};

}  // namespace

DisplayMethod trm_method() {
  return trm_frame_method(
      "trm", "Temporal Resolution Multiplexing: full and reduced frames alternate ((1 + r^2) / 2 of the pixels)",
      [](const EncoderConfig& link) { return std::make_unique<TrmSender>(link); });
}

}  // namespace trm::methods
