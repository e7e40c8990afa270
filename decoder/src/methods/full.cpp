// `full`: every frame rendered and sent at full resolution (the paper's "standard rendering", Table 1's reference).
#include "method_support.hpp"

namespace trm::methods {

DisplayMethod full_method() {
  return plain_frame_method(
      "full", "every frame rendered and sent at full resolution (the reference; 100 % pixels rendered and sent)",
      Between::Nothing);
}

}  // namespace trm::methods
