// Expected to fail: the exact product of a 40-bit and a 32-bit value needs 72 bits.
#include "trm/fixed.hpp"
using namespace trm::fx;
auto p = Fixed<16, 24, true>{} * Fixed<8, 24, true>{};
