// The rig file and COLMAP fuzz corpora replayed in the ordinary build
// (tests/fuzz_replay.h).

#include <gtest/gtest.h>

#include <fstream>

#include "cameras/colmap_model.h"
#include "cameras/colmap_rig.h"
#include "cameras/rig_json.h"
#include "core/json_util.h"
#include "fuzz/fuzz_files.h"
#include "tests/fuzz_replay.h"

namespace handlabel {
namespace {

TEST(ParserCorpus, RigJsonFuzzCorpusSmoke) {
  EXPECT_GE(testing::ReplayFuzzCorpus("rig_json",
                                      [](const std::string& bytes) {
                                        RigFromJson(ParseJsonStrict(bytes, "fuzz.json"),
                                                    "fuzz.json");
                                      }),
            2);
}

// As colmap_model_fuzz: first byte text (even) or binary, files joined by "@@@@".
TEST(ParserCorpus, ColmapModelFuzzCorpusSmoke) {
  const std::string dir = testing::ScratchDir();
  EXPECT_GE(
      testing::ReplayFuzzCorpus(
          "colmap_model",
          [&](const std::string& bytes) {
            if (bytes.empty()) return;
            const bool text = bytes[0] % 2 == 0;
            const auto parts = fuzz::SplitInput(bytes.substr(1), "@@@@", 3);
            const std::string ext = text ? ".txt" : ".bin";
            const char* names[] = {"cameras", "images", "points3D"};
            for (int i = 0; i < 3; ++i) {
              std::ofstream(dir + "/" + names[i] + ext, std::ios::binary) << parts[i];
            }
            const ColmapModel model = text ? ReadColmapText(dir) : ReadColmapBinary(dir);
            RigFromColmap(model, dir);
          }),
      2);
}

}  // namespace
}  // namespace handlabel
