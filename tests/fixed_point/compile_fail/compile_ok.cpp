// Control for the compile-failure tests: valid formats at the limits compile.
#include "trm/fixed.hpp"
using namespace trm::fx;
constexpr Fixed<1, 63, true> a = Fixed<1, 63, true>::max();
constexpr Fixed<0, 64, false> b = Fixed<0, 64, false>::lsb();
constexpr Fixed<-4, 12, false> c{};                      // 8 bits, value < 2^-4
constexpr Fixed<12, -4, true> d{};                       // 8 bits in steps of 16
constexpr auto p = Fixed<16, 16, true>{} * Fixed<16, 16, false>{};  // 64-bit product
static_assert(decltype(p)::width == 64);
int main() { return static_cast<int>(a.raw() + static_cast<std::int64_t>(b.raw()) + c.raw() + d.raw()); }
