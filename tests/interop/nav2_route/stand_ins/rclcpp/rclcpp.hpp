#pragma once
// Stand-in for the part of rclcpp that nav2_route's graph loader uses: a named logger and the two
// logging macros, which here append to a log the test reads (stand_ins/README in ../README.md).

#include <cstdio>
#include <string>

namespace rclcpp {

struct Logger {
  std::string name;
};

inline Logger get_logger(const std::string& name) { return Logger{name}; }

// Every message the loader logged, one per line, for the test to show.
inline std::string& stand_in_log() {
  static std::string log;
  return log;
}

template <class... Args>
void stand_in_print(const Logger& logger, const char* level, const char* format, Args... args) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, format, args...);
  stand_in_log() += "[" + logger.name + "] " + level + ": " + buf + "\n";
}

}  // namespace rclcpp

#define RCLCPP_INFO(logger, ...) ::rclcpp::stand_in_print(logger, "INFO", __VA_ARGS__)
#define RCLCPP_ERROR(logger, ...) ::rclcpp::stand_in_print(logger, "ERROR", __VA_ARGS__)
