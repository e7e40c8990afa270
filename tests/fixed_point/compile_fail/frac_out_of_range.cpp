// Expected to fail: binary point position beyond the supported [-1024, 1024].
#include "trm/fixed.hpp"
trm::fx::Fixed<-2000, 2008, false> x;
