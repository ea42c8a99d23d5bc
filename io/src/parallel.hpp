#pragma once
// Work on every index of a batch, spread over up to four cores (small batches on this thread).

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace lampnav::io {

template <class Fn>
void for_each_index(std::size_t n, Fn fn) {
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t i = next++; i < n; i = next++) fn(i);
  };
  const unsigned cores = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < cores && n > 64; ++k) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

}  // namespace lampnav::io
