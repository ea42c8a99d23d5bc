#pragma once
// One thread that runs the jobs given to it, in order, for as long as it lives. The node decodes
// each camera's images on one of these rather than on a thread started per image: glibc gives
// each thread a memory arena, and a thread started per image often lands on an arena whose pages
// were never touched, so that a megabyte of pixels costs 256 page faults (about 3 ms on this
// virtual machine, more than decoding the JPEG; docs/ros2.md, "Latency"). A thread kept for the
// node's life allocates each frame where the last one was freed. Private to the ros module.

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>

namespace lampnav::ros::detail {

class TaskThread {
 public:
  TaskThread();
  // Runs the jobs still queued, then joins.
  ~TaskThread();
  TaskThread(const TaskThread&) = delete;
  TaskThread& operator=(const TaskThread&) = delete;

  // Queues `f`; its result (or the exception it threw) comes out of the future.
  template <class F>
  auto submit(F f) -> std::future<decltype(f())> {
    using Result = decltype(f());
    auto task = std::make_shared<std::packaged_task<Result()>>(std::move(f));
    std::future<Result> result = task->get_future();
    push([task] { (*task)(); });
    return result;
  }

 private:
  void push(std::function<void()> job);
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  std::thread thread_;  // last: started once the rest is built
};

}  // namespace lampnav::ros::detail
