// `half-rate`: every other frame rendered and sent, each shown twice (Table 1 "Half frame rate": judder and strong
// hold-type blur, 50 % of the pixels).
#include "method_support.hpp"

namespace trm::methods {

DisplayMethod half_rate_method() {
  return plain_frame_method("half-rate", "every other frame rendered and sent, each shown twice (50 % pixels)",
                            Between::Repeat);
}

}  // namespace trm::methods
