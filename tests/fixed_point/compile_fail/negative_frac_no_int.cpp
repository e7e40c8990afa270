// Expected to fail: negative frac bits with no int bits leaves a negative width.
#include "trm/fixed.hpp"
trm::fx::Fixed<0, -4, false> x;
