// `bfi`: black-frame insertion. Every other frame rendered and sent; the frames between are black (Table 1: less
// hold-type blur, half the peak luminance, severe flicker; 50 % of the pixels).
#include "method_support.hpp"

namespace trm::methods {

DisplayMethod bfi_method() {
  return plain_frame_method(
      "bfi", "black-frame insertion: every other frame rendered and sent, black frames between (50 % pixels)",
      Between::Black);
}

}  // namespace trm::methods
