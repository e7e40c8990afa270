// The streaming decoder's line buffer: lines held by copy or in place, the schedule's reads checked either way.
#include "line_ring.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <stdexcept>

namespace trm::fixed_detail {
namespace {

TEST(LineRing, HoldsTheLastDepthLinesAndRefusesOthers) {
  LineRing<std::uint16_t> ring("test", 2, 3);
  EXPECT_THROW((void)ring.read(0), std::logic_error);  // never written
  for (int line = 0; line < 3; ++line) {
    std::uint16_t* slot = ring.write(line);
    for (int s = 0; s < 3; ++s) slot[s] = static_cast<std::uint16_t>(10 * line + s);
  }
  EXPECT_THROW((void)ring.read(0), std::logic_error);  // overwritten by line 2
  EXPECT_EQ(ring.read(1)[2], 12);
  EXPECT_EQ(ring.read(2)[0], 20);
  EXPECT_THROW((void)ring.read(3), std::logic_error);
  EXPECT_THROW((void)ring.write(-1), std::logic_error);
}

TEST(LineRing, AReferredLineIsReadInPlaceUntilItsSlotIsTaken) {
  LineRing<std::uint16_t> ring("test", 2, 3);
  const std::array<std::uint16_t, 3> outside{7, 8, 9};
  ring.refer(0, outside.data());
  EXPECT_EQ(ring.read(0), outside.data());
  std::uint16_t* own = ring.write(1);
  own[0] = own[1] = own[2] = 5;
  // Line 2 takes line 0's slot by write: it reads the slot's own storage, and the referred line is gone.
  std::uint16_t* slot = ring.write(2);
  slot[0] = slot[1] = slot[2] = 6;
  EXPECT_NE(ring.read(2), outside.data());
  EXPECT_EQ(ring.read(2)[1], 6);
  EXPECT_THROW((void)ring.read(0), std::logic_error);
  // And a referred line replaces a written one in the same way.
  ring.refer(3, outside.data());
  EXPECT_EQ(ring.read(3)[2], 9);
  EXPECT_EQ(ring.read(2)[0], 6);
  EXPECT_THROW((void)ring.refer(-1, outside.data()), std::logic_error);
}

TEST(LineRing, ACopyOwnsItsWrittenLinesAndSharesTheReferredOnes) {
  LineRing<std::int32_t> ring("test", 2, 2);
  const std::array<std::int32_t, 2> outside{-1, -2};
  ring.refer(0, outside.data());
  std::int32_t* own = ring.write(1);
  own[0] = 3;
  own[1] = 4;
  LineRing<std::int32_t> copy = ring;
  own[0] = 30;  // the original's line changes after the copy
  EXPECT_EQ(copy.read(1)[0], 3);
  EXPECT_NE(copy.read(1), ring.read(1));
  EXPECT_EQ(copy.read(0), outside.data());
  copy.write(2)[0] = 5;  // the copy's slot 0 now holds its own line 2; the original still refers line 0
  EXPECT_EQ(ring.read(0), outside.data());
  EXPECT_THROW((void)copy.read(0), std::logic_error);
}

}  // namespace
}  // namespace trm::fixed_detail
