// The job examples in the docs are jobs today: every code block of README.md and docs/
// that holds a labeling job (a top-level `input:` and `output:`; the body of a
// `cat > file <<TAG` heredoc when the block writes one) loads with LoadJobConfig, which
// rejects unknown keys and bad values by name. A renamed or removed job field then
// fails here, naming the doc and line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "pipeline/job_config.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

struct JobBlock {
  std::string where;  // doc:line
  std::string yaml;
};

// The heredoc's body if `block` writes one (`<<TAG` ... `TAG`), else the block.
std::string JobText(const std::string& block) {
  static const std::regex heredoc(R"(<<'?([A-Z]+)'?\n)");
  std::smatch m;
  if (!std::regex_search(block, m, heredoc)) return block;
  const size_t begin = m.position(0) + m.length(0);
  const size_t end = block.find("\n" + m[1].str() + "\n", begin - 1);
  return block.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

std::vector<JobBlock> DocJobBlocks() {
  const fs::path source(HANDLABEL_SOURCE_DIR);
  std::vector<fs::path> docs = {source / "README.md"};
  for (const auto& entry : fs::directory_iterator(source / "docs")) {
    if (entry.path().extension() == ".md") docs.push_back(entry.path());
  }
  static const std::regex input("(^|\n)input:"), output("(^|\n)output:");
  std::vector<JobBlock> blocks;
  for (const fs::path& doc : docs) {
    std::ifstream in(doc);
    std::string line, block;
    int line_number = 0, block_line = 0;
    bool inside = false;
    while (std::getline(in, line)) {
      ++line_number;
      if (line.rfind("```", 0) != 0) {
        if (inside) block += line + "\n";
        continue;
      }
      if (inside) {
        const std::string yaml = JobText(block);
        if (std::regex_search(yaml, input) && std::regex_search(yaml, output)) {
          blocks.push_back(
              {doc.filename().string() + ":" + std::to_string(block_line), yaml});
        }
        block.clear();
      }
      inside = !inside;
      block_line = line_number;
    }
  }
  return blocks;
}

TEST(DocJobExamples, EveryJobInTheDocsLoads) {
  const std::vector<JobBlock> blocks = DocJobBlocks();
  EXPECT_GE(blocks.size(), 4u);  // real-captures.md 1, labeling-jobs.md 3 today
  const fs::path dir = testing::ScratchDir();
  for (const JobBlock& b : blocks) {
    const fs::path path = dir / "job.yaml";
    std::ofstream(path) << b.yaml;
    try {
      const JobConfig job = LoadJobConfig(path.string());
      EXPECT_FALSE(job.output_dir.empty()) << b.where;
    } catch (const std::exception& e) {
      ADD_FAILURE() << b.where << ": " << e.what() << "\n" << b.yaml;
    }
  }
}

}  // namespace
}  // namespace handlabel
