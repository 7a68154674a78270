// Peer check against the real COLMAP binary (Debian package colmap): our writers'
// files must be read by COLMAP, and COLMAP's files by our readers, with every value
// unchanged.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "cameras/colmap_model.h"
#include "tests/cameras/rig_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::ExpectModelsEqual;
using testing::RandomColmapModel;
using testing::ScratchDir;

// Runs `colmap model_converter`; returns its exit status (log in `log`).
int ColmapConvert(const std::string& in, const std::string& out, const char* type,
                  const std::string& log) {
  const std::string command = "colmap model_converter --input_path '" + in +
                              "' --output_path '" + out + "' --output_type " + type +
                              " > '" + log + "' 2>&1";
  return std::system(command.c_str());
}

bool HaveColmap() { return std::system("colmap help > /dev/null 2>&1") == 0; }

TEST(ColmapPeer, ColmapReadsOurBinaryAndWeReadItsText) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap binary not installed (scripts/install-deps)";
  const ColmapModel model = RandomColmapModel();
  const std::string root = ScratchDir();
  fs::create_directories(root + "/bin");
  fs::create_directories(root + "/txt");
  WriteColmapBinary(model, root + "/bin");
  ASSERT_EQ(ColmapConvert(root + "/bin", root + "/txt", "TXT", root + "/log"), 0)
      << "see " << root << "/log";
  ExpectModelsEqual(model, ReadColmapText(root + "/txt"), 1e-15);
}

TEST(ColmapPeer, ColmapReadsOurTextAndWeReadItsBinary) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap binary not installed (scripts/install-deps)";
  const ColmapModel model = RandomColmapModel();
  const std::string root = ScratchDir();
  fs::create_directories(root + "/txt");
  fs::create_directories(root + "/bin");
  WriteColmapText(model, root + "/txt");
  ASSERT_EQ(ColmapConvert(root + "/txt", root + "/bin", "BIN", root + "/log"), 0)
      << "see " << root << "/log";
  ExpectModelsEqual(model, ReadColmapBinary(root + "/bin"), 1e-15);
}

}  // namespace
}  // namespace handlabel
