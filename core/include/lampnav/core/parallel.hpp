#pragma once
// Work on every index of a batch, spread over up to four cores (small batches on this thread).

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace lampnav {

// fn(state, i) for every i in [0, n), with one state per worker made by make_state() on that
// worker (for tools that are not thread-safe, a detector each). Indices are handed out in order.
template <class MakeState, class Fn>
void for_each_index(std::size_t n, MakeState make_state, Fn fn) {
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    auto state = make_state();
    for (std::size_t i = next++; i < n; i = next++) fn(state, i);
  };
  const unsigned cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < cores && n > 64; ++k) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

// fn(i) for every i in [0, n).
template <class Fn>
void for_each_index(std::size_t n, Fn fn) {
  for_each_index(
      n, [] { return 0; }, [&](int, std::size_t i) { fn(i); });
}

}  // namespace lampnav
