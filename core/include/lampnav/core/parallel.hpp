#pragma once
// Work on every index of a batch, spread over up to four cores (small batches on this thread).
// Results do not depend on the number of cores: each index is worked on alone, and callers keep
// what it gives in its own slot.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace lampnav {

namespace detail {
template <class MakeState, class Fn>
void for_each_index_spread(std::size_t n, std::size_t serial_up_to, MakeState& make_state, Fn& fn) {
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    auto state = make_state();
    for (std::size_t i = next++; i < n; i = next++) fn(state, i);
  };
  const unsigned cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < cores && k < n && n > serial_up_to; ++k) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}
}  // namespace detail

// fn(state, i) for every i in [0, n), with one state per worker made by make_state() on that
// worker (for tools that are not thread-safe, a detector each). Indices are handed out in order.
// Batches of up to 64 stay on this thread.
template <class MakeState, class Fn>
void for_each_index(std::size_t n, MakeState make_state, Fn fn) {
  detail::for_each_index_spread(n, 64, make_state, fn);
}

// fn(i) for every i in [0, n).
template <class Fn>
void for_each_index(std::size_t n, Fn fn) {
  for_each_index(
      n, [] { return 0; }, [&](int, std::size_t i) { fn(i); });
}

// fn(i) for every i in [0, n), for items that each take tens of microseconds or more: batches of
// more than `serial_up_to` are spread (a thread takes some 20 us to start and join).
template <class Fn>
void for_each_costly_index(std::size_t n, std::size_t serial_up_to, Fn fn) {
  auto no_state = [] { return 0; };
  auto each = [&](int, std::size_t i) { fn(i); };
  detail::for_each_index_spread(n, serial_up_to, no_state, each);
}

}  // namespace lampnav
