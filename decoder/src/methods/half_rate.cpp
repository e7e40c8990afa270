// `half-rate`: every other frame rendered and sent, each shown twice (Table 1 "Half frame rate": judder and strong
// hold-type blur, 50 % of the pixels).
#include "method_support.hpp"

namespace trm::methods {

namespace {

class HalfRateDisplay : public MethodDisplay {
 public:
  explicit HalfRateDisplay(const MethodSetup& setup) : panel_(setup.decoder.decoder) {}
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override {
    return panel_.show_received(frame, line_intact);
  }
  DecodedFrame show_lost(const FrameMeta& slot) override { return panel_.lost(slot); }
  // The frame between two rendered ones repeats the last one, code for code.
  DecodedFrame show_unsent(const FrameMeta& slot) override { return panel_.hold(slot); }

 private:
  PanelShow panel_;
};

}  // namespace

DisplayMethod half_rate_method() {
  DisplayMethod m;
  m.name = "half-rate";
  m.summary = "every other frame rendered and sent, each shown twice (50 % pixels rendered and sent)";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    require_no_option(setup, "half-rate");
    return std::make_unique<FullViewSender>(setup.decoder.decoder.link, false);
  };
  m.make_display = [](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    require_no_option(setup, "half-rate");
    return std::make_unique<HalfRateDisplay>(setup);
  };
  return m;
}

}  // namespace trm::methods
