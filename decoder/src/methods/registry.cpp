// The display-method registry: the list in methods.def, looked up by name.
#include "trm/display_method.hpp"

#include <stdexcept>

namespace trm {

namespace methods {
#define TRM_DISPLAY_METHOD(factory) DisplayMethod factory();
#include "methods.def"
#undef TRM_DISPLAY_METHOD
}  // namespace methods

const std::vector<DisplayMethod>& display_methods() {
  static const std::vector<DisplayMethod> all = {
#define TRM_DISPLAY_METHOD(factory) methods::factory(),
#include "methods.def"
#undef TRM_DISPLAY_METHOD
  };
  return all;
}

MethodChoice find_display_method(const std::string& spec) {
  const std::size_t colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  MethodChoice choice;
  if (colon != std::string::npos) {
    choice.option = spec.substr(colon + 1);
    if (choice.option.empty()) throw std::invalid_argument("method '" + spec + "': empty option after ':'");
  }
  for (const DisplayMethod& method : display_methods()) {
    if (method.name != name) continue;
    if (method.option_help.empty() && !choice.option.empty()) {
      throw std::invalid_argument("method '" + name + "' takes no option, got '" + choice.option + "'");
    }
    choice.method = &method;
    return choice;
  }
  std::string list;
  for (const DisplayMethod& method : display_methods()) list += (list.empty() ? "" : ", ") + method.name;
  throw std::invalid_argument("unknown method '" + name + "' (available: " + list + "; `trm methods` describes them)");
}

void check_display_method(const std::string& spec, const std::string& impl) {
  const MethodChoice choice = find_display_method(spec);
  check_decoder_name(impl);
  if (!choice.method->fixed_point && impl != "reference") {
    throw std::invalid_argument("method '" + choice.method->name +
                                "' shows plain frames and has no fixed-point decoder: leave --impl out or use "
                                "--impl reference");
  }
  // Each side refuses an option it does not know; nothing is built that the check would not also build.
  MethodSetup setup;
  setup.option = choice.option;
  setup.impl = "reference";
  (void)choice.method->make_sender(setup);
}

FrameMeta view_meta_of(std::int64_t t, int eye, Parity parity, cv::Size sent, cv::Size full, const EncoderConfig& link) {
  FrameMeta meta;
  meta.index = t;
  meta.eye = eye;
  meta.parity = parity;
  meta.width = sent.width;
  meta.height = sent.height;
  meta.full_width = full.width;
  meta.full_height = full.height;
  meta.bits = link.bits;
  meta.transfer = link.transfer;
  return meta;
}

FrameMeta unsent_slot(std::int64_t t, int eye, cv::Size full, const EncoderConfig& link) {
  return view_meta_of(t, eye, parity_of(t, eye, link), full, full, link);
}

}  // namespace trm
