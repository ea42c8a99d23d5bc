#pragma once
// Shared by the ros tests: a DDS domain of the test's own, and waiting with a deadline.

#include <unistd.h>

#include <chrono>
#include <functional>
#include <initializer_list>
#include <string>
#include <thread>

#include "lampnav/ros/participant.hpp"

namespace lampnav::test {

// A domain no other test process uses at the same time (ctest runs tests in parallel).
inline int test_domain() { return 1 + static_cast<int>(::getpid() % 230); }

// Whether `readers` has matched a publisher on each of `topics`. A writer's matched() tells its
// own side only: a reader takes samples only from writers it has matched in turn, and a
// best-effort sample sent before then is lost (a test under load lost two odometry messages so).
inline bool readers_matched(const ros::Participant& readers,
                            std::initializer_list<std::string> topics) {
  for (const std::string& t : topics)
    if (readers.publishers_matched(t) == 0) return false;
  return true;
}

// Waits until `done` or `seconds` pass; whether it was done.
inline bool wait_for(const std::function<bool()>& done, double seconds = 10) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

}  // namespace lampnav::test
