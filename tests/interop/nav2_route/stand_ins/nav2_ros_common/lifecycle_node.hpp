#pragma once
// Stand-in for nav2::LifecycleNode: the loader's configure() only asks it for a logger.

#include <memory>
#include <string>

#include "rclcpp/rclcpp.hpp"

namespace nav2 {

class LifecycleNode {
 public:
  using SharedPtr = std::shared_ptr<LifecycleNode>;
  explicit LifecycleNode(std::string name) : name_(std::move(name)) {}
  rclcpp::Logger get_logger() const { return rclcpp::get_logger(name_); }

 private:
  std::string name_;
};

}  // namespace nav2
