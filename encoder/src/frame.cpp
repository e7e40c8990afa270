#include "trm/frame.hpp"

#include <stdexcept>

namespace trm {

const char* to_string(Parity p) { return p == Parity::Full ? "full" : "reduced"; }

const char* to_string(Transfer t) { return t == Transfer::Srgb ? "srgb" : "gamma2.2"; }

const char* to_string(ResampleSpace s) { return s == ResampleSpace::Encoded ? "encoded" : "linear"; }

Transfer parse_transfer(const std::string& name) {
  if (name == "srgb") return Transfer::Srgb;
  if (name == "gamma2.2") return Transfer::Gamma22;
  throw std::invalid_argument("unknown transfer function '" + name + "' (expected srgb or gamma2.2)");
}

ResampleSpace parse_resample_space(const std::string& name) {
  if (name == "encoded") return ResampleSpace::Encoded;
  if (name == "linear") return ResampleSpace::Linear;
  throw std::invalid_argument("unknown resample space '" + name + "' (expected encoded or linear)");
}

}  // namespace trm
