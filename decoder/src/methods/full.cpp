// `full`: every frame rendered and sent at full resolution (the paper's "standard rendering", Table 1's reference).
#include "method_support.hpp"

#include <stdexcept>

namespace trm::methods {

namespace {

class FullDisplay : public MethodDisplay {
 public:
  explicit FullDisplay(const MethodSetup& setup) : panel_(setup.decoder.decoder) {}
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override {
    return panel_.show_received(frame, line_intact);
  }
  DecodedFrame show_lost(const FrameMeta& slot) override { return panel_.lost(slot); }
  DecodedFrame show_unsent(const FrameMeta&) override {
    throw std::logic_error("full: every view is sent");
  }

 private:
  PanelShow panel_;
};

}  // namespace

DisplayMethod full_method() {
  DisplayMethod m;
  m.name = "full";
  m.summary = "every frame rendered and sent at full resolution (the reference; 100 % pixels rendered and sent)";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    require_no_option(setup, "full");
    return std::make_unique<FullViewSender>(setup.decoder.decoder.link, true);
  };
  m.make_display = [](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    require_no_option(setup, "full");
    return std::make_unique<FullDisplay>(setup);
  };
  return m;
}

}  // namespace trm::methods
