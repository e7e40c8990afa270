// The fixed_point module's public interface in one include (see docs/fixed_point.md).
#pragma once

#include "trm/fixed.hpp"          // Fixed<IntBits, FracBits, Signed, Q, O>, divide, shifts
#include "trm/fixed_runtime.hpp"  // RuntimeFormat, quantise_raw, multiply_raw, quantise_double
#include "trm/fx_quantise.hpp"    // Quant, Overflow, SaturationCounter
#include "trm/lut.hpp"            // InterpolatedLut, LutShape, make_*_lut
