// Expected to fail: the exact sum of two 64-bit values needs 65 bits.
#include "trm/fixed.hpp"
using namespace trm::fx;
auto s = Fixed<64, 0, true>{} + Fixed<64, 0, true>{};
