// The stage vocabulary's names (trm/decoder.hpp).
#include "trm/decoder.hpp"

namespace trm {

const char* stage_name(Stage stage) {
  switch (stage) {
    case Stage::Codes: return "codes";
    case Stage::Linear: return "I";
    case Stage::Reduced: return "d";
    case Stage::LowPass: return "L";
    case Stage::Beta: return "beta";
    case Stage::Shown: return "shown";
    case Stage::Residual: return "rho";
    case Stage::Alpha: return "alpha";
    case Stage::PreviousLowPass: return "L_prev";
    case Stage::Contrast: return "c";
    case Stage::Weight: return "w";
    case Stage::AlphaPrime: return "alpha_prime";
    case Stage::Drive: return "drive";
    case Stage::AlphaUnclamped: return "alpha_unclamped";
    case Stage::LcdTarget: return "lcd_m";
    case Stage::LcdPreviousDrive: return "lcd_v_prev";
    case Stage::LcdPreviousLinear: return "lcd_x_prev";
    case Stage::LcdUnreachable: return "lcd_unreachable";
  }
  return "?";
}

}  // namespace trm
