#include "lampnav/core/time.hpp"
#include "lampnav_test.hpp"

namespace lampnav {
namespace {

TEST(Time, NanosecondRoundTrips) {
  const Stamp t = stamp_from_nanoseconds(1'700'000'000'123'456'789LL);
  EXPECT_EQ(to_nanoseconds(t), 1'700'000'000'123'456'789LL);
  EXPECT_EQ(to_nanoseconds(t + std::chrono::milliseconds(1)), 1'700'000'000'124'456'789LL);
  EXPECT_EQ(to_nanoseconds(duration_from_seconds(1.5)), 1'500'000'000LL);
  EXPECT_EQ(to_nanoseconds(stamp_from_seconds(-0.25)), -250'000'000LL);
  EXPECT_DOUBLE_EQ(to_seconds(Duration(2'500'000'000LL)), 2.5);
}

TEST(Time, StampsOrderAndSubtract) {
  const Stamp a = stamp_from_seconds(10.0);
  const Stamp b = stamp_from_seconds(11.25);
  EXPECT_LT(a, b);
  EXPECT_EQ(b - a, duration_from_seconds(1.25));
}

}  // namespace
}  // namespace lampnav
