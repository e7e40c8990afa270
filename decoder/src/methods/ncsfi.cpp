// `ncsfi`: nonlinearity compensated smooth frame insertion as the paper adapted it for VR (Sec. 8): every other frame
// rendered; each rendered frame is shown sharpened and then blurred (the blurred one is TRM's reduced frame, D of
// the same codes, so the blur is TRM's), and the residual is always added, whatever the motion (s = 0). Same link
// payload as TRM, half the rendering; ghosting where TRM's motion test would keep the residual out.
#include "method_support.hpp"

#include <map>

namespace trm::methods {

namespace {

class NcsfiSender : public MethodSender {
 public:
  explicit NcsfiSender(const EncoderConfig& link) : encoder_(link) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    return trm_view_meta(t, eye, full, encoder_.config());
  }
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    const EncoderConfig& link = encoder_.config();
    Transmission out;
    auto rendered = last_full_codes_.find(eye);
    if (parity_of(t, eye, link) == Parity::Full || rendered == last_full_codes_.end()) {
      // A rendered frame; a stream that starts on a blurred slot renders that one too.
      const LinkFrame full = encoder_.encode_as(Parity::Full, linear, t, eye);
      out.pixels_rendered = static_cast<std::int64_t>(full.codes.total());
      last_full_codes_[eye] = full.codes;
      if (parity_of(t, eye, link) == Parity::Full) {
        out.frame = full;
        return out;
      }
      rendered = last_full_codes_.find(eye);
    }
    // The blurred frame of the last rendered frame, at TRM's reduced size: nothing new is rendered.
    out.frame.codes = reduce_codes(rendered->second, link);
    FrameMeta& meta = out.frame.meta;
    meta.index = t;
    meta.eye = eye;
    meta.parity = Parity::Reduced;
    meta.full_width = rendered->second.cols;
    meta.full_height = rendered->second.rows;
    meta.width = out.frame.codes.cols;
    meta.height = out.frame.codes.rows;
    meta.bits = link.bits;
    meta.transfer = link.transfer;
    return out;
  }

 private:
  TrmEncoder encoder_;
  std::map<int, cv::Mat> last_full_codes_;  // per eye: the codes of the last rendered (sharp) frame
};

FixedDecoderConfig always_add_residual(FixedDecoderConfig config) {
  config.decoder.sensitivity = 0.0;  // w = exp(-0 c) = 1: the residual is added regardless of motion
  return config;
}

}  // namespace

DisplayMethod ncsfi_method() {
  return trm_frame_method(
      "ncsfi", "NCSFI (Sec. 8): each rendered frame shown sharpened then blurred, residual always added (s = 0)",
      [](const EncoderConfig& link) { return std::make_unique<NcsfiSender>(link); }, always_add_residual);
}

}  // namespace trm::methods
