// The thread a camera's images are decoded on: its jobs run in order on one thread that lives as
// long as it does, a job's exception reaches its future, and jobs still queued when it goes are
// run, not dropped.

#include "task_thread.hpp"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "lampnav_test.hpp"

namespace lampnav::ros::detail {
namespace {

TEST(TaskThread, RunsJobsInOrderOnOneThreadOfItsOwn) {
  TaskThread t;
  std::vector<std::future<std::thread::id>> ids;
  std::vector<int> order;  // written by the jobs only, read after the last one is done
  for (int k = 0; k < 50; ++k)
    ids.push_back(t.submit([k, &order] {
      order.push_back(k);
      return std::this_thread::get_id();
    }));
  const std::thread::id first = ids.front().get();
  EXPECT_NE(first, std::this_thread::get_id());
  for (std::size_t k = 1; k < ids.size(); ++k) EXPECT_EQ(ids[k].get(), first);
  ASSERT_EQ(order.size(), 50u);
  for (int k = 0; k < 50; ++k) EXPECT_EQ(order[k], k);
  // The same thread again later: it is kept, not started per job.
  EXPECT_EQ(t.submit([] { return std::this_thread::get_id(); }).get(), first);
}

TEST(TaskThread, AJobsExceptionReachesItsFutureAndTheNextJobRuns) {
  TaskThread t;
  auto bad = t.submit([]() -> int { throw std::runtime_error("damaged frame"); });
  auto good = t.submit([] { return 7; });
  EXPECT_THROW(bad.get(), std::runtime_error);
  EXPECT_EQ(good.get(), 7);
}

TEST(TaskThread, RunsTheJobsStillQueuedWhenItGoes) {
  std::atomic<int> ran{0};
  std::promise<void> go;
  std::shared_future<void> gate = go.get_future().share();
  std::thread opener;
  {
    TaskThread t;
    t.submit([gate] { gate.wait(); });  // holds the thread while the rest queue up
    for (int k = 0; k < 20; ++k) t.submit([&ran] { ++ran; });
    // The gate opens once the destructor below has told the thread to stop.
    opener = std::thread([&go] {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      go.set_value();
    });
  }  // destroyed with 20 jobs queued
  opener.join();
  EXPECT_EQ(ran.load(), 20);
}

}  // namespace
}  // namespace lampnav::ros::detail
