#include "lampnav/core/parallel.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>

namespace lampnav::detail {

unsigned cores() { return std::max(1u, std::min(4u, std::thread::hardware_concurrency())); }

namespace {

// Workers that stay, for work a frame at a time: waking one costs microseconds where starting a
// thread costs tens. The caller works too and waits only for the items a worker has taken, never
// for a worker to be scheduled: on a busy machine it does the whole batch itself.
class WorkerPool {
 public:
  WorkerPool() {
    for (unsigned k = 1; k < cores(); ++k) workers_.emplace_back([this] { work(); });
  }
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> l(m_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
  }
  bool empty() const { return workers_.empty(); }

  void run(std::size_t n, const std::function<void(std::size_t)>& fn) {
    auto job = std::make_shared<Job>();
    job->n = n;
    job->fn = &fn;
    {
      std::lock_guard<std::mutex> l(m_);
      job_ = job;
      ++generation_;
    }
    wake_.notify_all();
    std::exception_ptr mine;
    try {
      for (std::size_t i = job->next++; i < n; i = job->next++) fn(i);
    } catch (...) {
      mine = std::current_exception();
      job->next = n;  // nothing more is started
    }
    {
      std::unique_lock<std::mutex> l(job->m);
      job->done.wait(l, [&] { return job->in_flight == 0; });
    }
    {
      std::lock_guard<std::mutex> l(m_);
      if (job_ == job) job_.reset();
    }
    if (mine) std::rethrow_exception(mine);
    if (job->failed) std::rethrow_exception(job->failed);
  }

 private:
  struct Job {
    std::size_t n = 0;
    const std::function<void(std::size_t)>* fn = nullptr;  // valid while an item is unclaimed
    std::atomic<std::size_t> next{0};
    std::atomic<int> in_flight{0};  // workers inside the job (counted before they claim)
    std::mutex m;
    std::condition_variable done;
    std::exception_ptr failed;  // a worker's, under m
  };

  void work() {
    std::uint64_t seen = 0;
    for (;;) {
      std::shared_ptr<Job> job;
      {
        std::unique_lock<std::mutex> l(m_);
        wake_.wait(l, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        job = job_;
      }
      if (!job) continue;
      // Counted first, then claimed: the caller, once every index is claimed, waits for this
      // count, so an item is never run after the caller returned.
      ++job->in_flight;
      try {
        for (std::size_t i = job->next++; i < job->n; i = job->next++) (*job->fn)(i);
      } catch (...) {
        std::lock_guard<std::mutex> l(job->m);
        if (!job->failed) job->failed = std::current_exception();
        job->next = job->n;
      }
      std::lock_guard<std::mutex> l(job->m);
      if (--job->in_flight == 0) job->done.notify_all();
    }
  }

  std::mutex m_;
  std::condition_variable wake_;
  std::shared_ptr<Job> job_;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

WorkerPool& pool() {
  static WorkerPool p;
  return p;
}

}  // namespace

void for_each_on_pool(std::size_t n, std::size_t serial_up_to,
                      const std::function<void(std::size_t)>& fn) {
  if (n <= serial_up_to || pool().empty()) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  pool().run(n, fn);
}

}  // namespace lampnav::detail
