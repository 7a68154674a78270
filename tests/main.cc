// Shared GoogleTest main: re-seeds the test random generator before every test from a
// hash of the test's full name, and prints the seed when a test fails.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>

#include "core/blas_library.h"
#include "core/random.h"
#include "tests/test_util.h"

namespace handlabel::testing {
namespace {

// The running test's private folder (ScratchDir); removed when the test passes.
std::filesystem::path ScratchPath(const ::testing::TestInfo& info) {
  // Parameterised tests have '/' in their names: keep the folder one level deep.
  std::string name = std::string(info.test_suite_name()) + "_" + info.name();
  std::replace(name.begin(), name.end(), '/', '_');
  return std::filesystem::temp_directory_path() /
         ("handlabel_" + name + "_" + std::to_string(::getpid()));
}

std::mt19937_64 g_rng;
uint64_t g_seed = 0;

class SeedPerTest : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo& info) override {
    // Stable across compilers (std::hash is not).
    const uint64_t h = Fnv1a64(std::string(info.test_suite_name()) + "." + info.name());
    g_seed = h;
    g_rng.seed(h);
  }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (info.result()->Failed()) {
      std::cerr << "  test seed: " << g_seed << "\n";
      return;  // the scratch folder stays for inspection
    }
    std::error_code ignored;
    std::filesystem::remove_all(ScratchPath(info), ignored);
  }
};

}  // namespace

std::mt19937_64& TestRng() { return g_rng; }
uint64_t TestSeed() { return g_seed; }

std::string ScratchDir() {
  const ::testing::TestInfo* info =
      ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = ScratchPath(*info);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::map<std::string, std::string> FilesUnder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file())
      files[fs::relative(e.path(), dir).string()] = ReadFileBytes(e.path().string());
  }
  return files;
}

}  // namespace handlabel::testing

int main(int argc, char** argv) {
  ::testing::InitGoogleMock(&argc, argv);
  // As the program does (apps/command_table.cc); ConcurrentProducts.* fail on such a
  // BLAS, the other tests run so that the rest of the picture is seen.
  if (const auto problem = handlabel::PrepareBlasForThreads()) {
    std::cerr << "warning: " << *problem << "\n";
  }
  ::testing::UnitTest::GetInstance()->listeners().Append(
      new handlabel::testing::SeedPerTest);
  return RUN_ALL_TESTS();
}
