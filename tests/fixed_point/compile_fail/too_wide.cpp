// Expected to fail: 65 bits exceed the 64-bit backing integer.
#include "trm/fixed.hpp"
trm::fx::Fixed<40, 25, true> x;
