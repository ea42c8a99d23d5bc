#pragma once
// Running the `lampnav` program from a test: exit status, stdout and stderr.

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "lampnav_test.hpp"

namespace lampnav::test {

struct CliResult {
  int status = -1;
  std::string out, err;
};

// Runs lampnav with arguments (shell-quoted by the caller), capturing stdout and stderr.
inline CliResult run_lampnav(const std::string& args) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string err_file = (dir / ("lampnav_cli_err_" + std::to_string(::getpid()))).string();
  const std::string cmd = std::string(LAMPNAV_BINARY) + " " + args + " 2>" + err_file;
  CliResult r;
  r.out = run_command(cmd, &r.status);
  r.err = slurp(err_file);
  std::filesystem::remove(err_file);
  return r;
}

// A source-tree path, quoted for the shell.
inline std::string quoted_source(const std::string& rel) { return "'" + source_path(rel) + "'"; }

}  // namespace lampnav::test
