// Every harness over its seed corpus and over every input a fuzzer ever found a fault with
// (tests/fuzz/regressions/<harness>/): the contract holds on each (a broken one aborts).

#include <filesystem>
#include <fstream>
#include <iterator>

#include "harnesses.hpp"
#include "lampnav_test.hpp"

namespace lampnav::fuzz {
namespace {

namespace fs = std::filesystem;

std::size_t run_folder(const Named& h, const std::string& folder) {
  if (!fs::exists(folder)) return 0;
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(folder)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    h.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    ++n;
  }
  return n;
}

TEST(FuzzCorpus, EveryHarnessHoldsItsContractOnItsCorpusAndRegressions) {
  for (const auto& h : all()) {
    const std::size_t seeds =
        run_folder(h, test::source_path(std::string("tests/fuzz/corpus/") + h.name));
    const std::size_t regressions =
        run_folder(h, test::source_path(std::string("tests/fuzz/regressions/") + h.name));
    std::cout << h.name << ": " << seeds << " seeds, " << regressions << " regressions\n";
    EXPECT_GT(seeds, 0u) << h.name << " has no seed corpus";
  }
}

}  // namespace
}  // namespace lampnav::fuzz
