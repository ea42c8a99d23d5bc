#pragma once
// Stand-in for nav2_core's route exceptions: the loader throws NoValidGraph on an edge that names
// no node.

#include <stdexcept>
#include <string>

namespace nav2_core {

struct NoValidGraph : std::runtime_error {
  explicit NoValidGraph(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace nav2_core
