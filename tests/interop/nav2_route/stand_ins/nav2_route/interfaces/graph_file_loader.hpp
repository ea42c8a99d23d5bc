#pragma once
// Stand-in for nav2_route's GraphFileLoader plugin interface.

#include <memory>
#include <string>

#include "nav2_ros_common/lifecycle_node.hpp"
#include "nav2_route/types.hpp"
#include "rclcpp/rclcpp.hpp"

namespace nav2_route {

class GraphFileLoader {
 public:
  using Ptr = std::shared_ptr<GraphFileLoader>;
  virtual ~GraphFileLoader() = default;
  virtual void configure(const nav2::LifecycleNode::SharedPtr node) = 0;
  virtual bool loadGraphFromFile(Graph& graph, GraphToIDMap& graph_to_id_map,
                                 std::string filepath) = 0;
};

}  // namespace nav2_route
