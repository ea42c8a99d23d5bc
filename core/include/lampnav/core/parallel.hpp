#pragma once
// Work on every index of a batch, spread over up to four cores. Batch jobs start threads of
// their own (for_each_index); a frame's work goes to workers that stay (for_each_costly_index).
// Results do not depend on the number of cores when each index is worked on alone and callers
// keep what it gives in its own slot.

#include <atomic>
#include <cstddef>
#include <functional>
#include <thread>
#include <vector>

namespace lampnav {

namespace detail {
// The cores a batch is spread over: this machine's, at least one and at most four.
unsigned cores();
void for_each_on_pool(std::size_t n, std::size_t serial_up_to,
                      const std::function<void(std::size_t)>& fn);
}  // namespace detail

// fn(state, i) for every i in [0, n), with one state per worker made by make_state() on that
// worker (for tools that are not thread-safe, a detector each). Indices are handed out in order.
// Batches of up to 64 stay on this thread.
template <class MakeState, class Fn>
void for_each_index(std::size_t n, MakeState make_state, Fn fn) {
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    auto state = make_state();
    for (std::size_t i = next++; i < n; i = next++) fn(state, i);
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < detail::cores() && n > 64; ++k) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

// fn(i) for every i in [0, n).
template <class Fn>
void for_each_index(std::size_t n, Fn fn) {
  for_each_index(
      n, [] { return 0; }, [&](int, std::size_t i) { fn(i); });
}

// fn(i) for every i in [0, n), for items that each take tens of microseconds or more, a frame's
// work at a time: batches of more than `serial_up_to` are shared with workers that stay (up to
// three, one per other core). The caller works too, and never waits for a worker that has not
// started; fn must be safe to call from several threads at once. An exception from fn stops the
// batch and is thrown here once no item runs.
template <class Fn>
void for_each_costly_index(std::size_t n, std::size_t serial_up_to, Fn fn) {
  detail::for_each_on_pool(n, serial_up_to, std::function<void(std::size_t)>(std::ref(fn)));
}

}  // namespace lampnav
