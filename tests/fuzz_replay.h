#pragma once
// Replays a fuzz target's kept corpus (fuzz/corpus/<name>/) through the same reader in
// the ordinary test build (no clang needed), plus seeded random byte edits of each
// input: every input must decode or throw InputError, never anything else.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel::testing {

// Runs `read` on every corpus file and on `edits` mutated copies of each; returns how
// many corpus files there were.
inline int ReplayFuzzCorpus(const std::string& name,
                            const std::function<void(const std::string&)>& read,
                            int edits = 20) {
  const std::string dir = std::string(HANDLABEL_SOURCE_DIR) + "/fuzz/corpus/" + name;
  int files = 0;
  const auto run = [&](const std::string& bytes, const std::string& what) {
    try {
      read(bytes);
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": not an InputError: " << e.what();
    }
  };
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string bytes = ReadFileBytes(entry.path().string());
    ++files;
    run(bytes, entry.path().string());
    for (int e = 0; e < edits && !bytes.empty(); ++e) {
      std::string edited = bytes;
      const int changes = static_cast<int>(Uniform(1, 4));
      for (int c = 0; c < changes; ++c) {
        const size_t at = static_cast<size_t>(Uniform(0, edited.size() - 0.5));
        edited[at] = static_cast<char>(Uniform(0, 256));
      }
      if (Uniform(0, 1) < 0.3)
        edited.resize(static_cast<size_t>(Uniform(0, edited.size())));
      run(edited, entry.path().string() + " edit " + std::to_string(e));
    }
  }
  return files;
}

}  // namespace handlabel::testing
