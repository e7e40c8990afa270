// Expected to fail: a format with no bits.
#include "trm/fixed.hpp"
trm::fx::Fixed<0, 0, true> x;
