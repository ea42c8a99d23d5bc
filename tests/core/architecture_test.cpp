// The module graph of docs/architecture.md against the CMake links, and the rules it states.

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "lampnav_test.hpp"

namespace lampnav {
namespace {

namespace fs = std::filesystem;
using Graph = std::map<std::string, std::set<std::string>>;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "module -> dep dep ..." lines of the page's first code block.
Graph documented() {
  const std::string page = read_text(test::source_path("docs/architecture.md"));
  const auto open = page.find("```\n");
  const auto close = page.find("```", open + 4);
  std::istringstream block(page.substr(open + 4, close - open - 4));
  Graph g;
  for (std::string line; std::getline(block, line);) {
    std::istringstream words(line);
    std::string module, arrow, dep;
    if (!(words >> module >> arrow) || arrow != "->") continue;
    auto& deps = g[module];
    while (words >> dep) deps.insert(dep);
  }
  return g;
}

// The lampnav:: targets each module's lampnav_module() call links, public or private.
Graph linked(const std::set<std::string>& modules) {
  Graph g;
  const std::regex dep(R"(lampnav::(\w+))");
  for (const auto& m : modules) {
    const std::string text = read_text(test::source_path(m + "/CMakeLists.txt"));
    const auto start = text.find("lampnav_module(" + m);
    EXPECT_NE(start, std::string::npos) << m;
    const std::string call = text.substr(start, text.find(')', start) - start);
    auto& deps = g[m];
    for (std::sregex_iterator it(call.begin(), call.end(), dep), end; it != end; ++it) {
      const std::string name = (*it)[1];
      if (name != "json_internal") deps.insert(name);
    }
  }
  return g;
}

std::set<std::string> reachable(const Graph& g, const std::string& from) {
  std::set<std::string> seen;
  std::vector<std::string> todo{from};
  while (!todo.empty()) {
    const std::string m = todo.back();
    todo.pop_back();
    const auto it = g.find(m);
    if (it == g.end()) continue;
    for (const auto& d : it->second)
      if (seen.insert(d).second) todo.push_back(d);
  }
  return seen;
}

// Files under `dir` that include a header of module `other`.
std::vector<std::string> including(const std::string& dir, const std::string& other) {
  std::vector<std::string> found;
  const std::string needle = "#include \"lampnav/" + other + "/";
  for (const auto& e : fs::recursive_directory_iterator(test::source_path(dir))) {
    if (!e.is_regular_file()) continue;
    const auto ext = e.path().extension();
    if (ext != ".cpp" && ext != ".hpp") continue;
    if (read_text(e.path().string()).find(needle) != std::string::npos)
      found.push_back(e.path().string());
  }
  return found;
}

TEST(Architecture, ModuleLinksAreTheOnesThisPageLists) {
  const Graph doc = documented();
  ASSERT_GE(doc.size(), 10u);
  std::set<std::string> modules;
  for (const auto& [m, deps] : doc) modules.insert(m);
  const Graph cmake = linked(modules);
  for (const auto& m : modules) {
    EXPECT_EQ(doc.at(m), cmake.at(m))
        << m << ": docs/architecture.md and " << m << "/CMakeLists.txt disagree";
    EXPECT_FALSE(reachable(cmake, m).count(m)) << m << " depends on itself";
  }
}

TEST(Architecture, WhatRunsOnTheRobotLinksNoLogFormatsAndSimNeverUsesNavigation) {
  const Graph g = linked({"core", "graph", "vision", "io", "fusion", "navigation", "sim"});
  // io is where OpenCV's codecs and zstd are linked.
  EXPECT_FALSE(reachable(g, "navigation").count("io"));
  EXPECT_FALSE(reachable(g, "sim").count("navigation"));
  EXPECT_TRUE(including("sim", "navigation").empty()) << including("sim", "navigation").front();
  EXPECT_TRUE(including("navigation", "io").empty()) << including("navigation", "io").front();
  EXPECT_TRUE(including("navigation", "evaluation").empty());
}

}  // namespace
}  // namespace lampnav
