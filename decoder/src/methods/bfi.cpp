// `bfi`: black-frame insertion. Every other frame rendered and sent; the frames between are black (Table 1: less
// hold-type blur, half the peak luminance, severe flicker; 50 % of the pixels).
#include "method_support.hpp"

namespace trm::methods {

namespace {

class BlackFrameDisplay : public MethodDisplay {
 public:
  explicit BlackFrameDisplay(const MethodSetup& setup) : panel_(setup.decoder.decoder) {}
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override {
    return panel_.show_received(frame, line_intact);
  }
  DecodedFrame show_lost(const FrameMeta& slot) override { return panel_.lost(slot); }
  DecodedFrame show_unsent(const FrameMeta& slot) override { return panel_.black(slot); }

 private:
  PanelShow panel_;
};

}  // namespace

DisplayMethod bfi_method() {
  DisplayMethod m;
  m.name = "bfi";
  m.summary = "black-frame insertion: every other frame rendered and sent, black frames between (50 % pixels)";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    require_no_option(setup, "bfi");
    return std::make_unique<FullViewSender>(setup.decoder.decoder.link, false);
  };
  m.make_display = [](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    require_no_option(setup, "bfi");
    return std::make_unique<BlackFrameDisplay>(setup);
  };
  return m;
}

}  // namespace trm::methods
