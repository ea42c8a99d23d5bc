// Work spread over cores: every index once, in any order, whatever the machine; an item's
// exception reaches the caller only when no item runs any more.

#include "lampnav/core/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace lampnav {
namespace {

TEST(Parallel, CostlyIndicesAreEachWorkedOnOnce) {
  for (const std::size_t n : {0u, 1u, 3u, 4u, 100u, 5000u}) {
    std::vector<std::atomic<int>> hits(n);
    for_each_costly_index(n, 3, [&](std::size_t i) {
      ++hits[i];
      // Long enough for a worker to wake up and take some.
      const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(20);
      while (std::chrono::steady_clock::now() < until) {
      }
    });
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(hits[i].load(), 1) << "n " << n << " i " << i;
  }
}

TEST(Parallel, SmallBatchesStayOnTheCallingThread) {
  std::vector<std::thread::id> ids(5);
  for_each_costly_index(ids.size(), 5, [&](std::size_t i) { ids[i] = std::this_thread::get_id(); });
  for (const auto& id : ids) EXPECT_EQ(id, std::this_thread::get_id());
}

TEST(Parallel, AnItemsExceptionReachesTheCallerOnceNothingRuns) {
  std::atomic<int> running{0}, after{0};
  std::atomic<bool> returned{false};
  EXPECT_THROW(for_each_costly_index(2000, 1,
                                     [&](std::size_t i) {
                                       ++running;
                                       if (returned) ++after;
                                       std::this_thread::sleep_for(std::chrono::microseconds(50));
                                       --running;
                                       if (i == 10) throw std::runtime_error("item 10");
                                     }),
               std::runtime_error);
  returned = true;
  EXPECT_EQ(running.load(), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(after.load(), 0);
  EXPECT_EQ(running.load(), 0);
}

TEST(Parallel, CallersOnSeveralThreadsEachGetTheirWholeBatch) {
  std::vector<std::vector<int>> out(4, std::vector<int>(3000, 0));
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&, c] {
      for (int round = 0; round < 20; ++round)
        for_each_costly_index(out[c].size(), 2, [&](std::size_t i) { out[c][i] += 1; });
    });
  for (auto& t : callers) t.join();
  for (int c = 0; c < 4; ++c)
    for (std::size_t i = 0; i < out[c].size(); ++i) ASSERT_EQ(out[c][i], 20) << c << " " << i;
}

}  // namespace
}  // namespace lampnav
