// The capture JSON fuzz corpus replayed in the ordinary build (tests/fuzz_replay.h).

#include <gtest/gtest.h>

#include "capture/capture_format.h"
#include "core/json_util.h"
#include "tests/fuzz_replay.h"

namespace handlabel {
namespace {

// As capture_json_fuzz: the first byte picks manifest, keypoints or ground truth.
TEST(CaptureJson, FuzzCorpusSmoke) {
  EXPECT_GE(testing::ReplayFuzzCorpus("capture_json",
                                      [](const std::string& bytes) {
                                        if (bytes.empty()) return;
                                        const nlohmann::json j =
                                            ParseJsonStrict(bytes.substr(1), "fuzz.json");
                                        switch (static_cast<uint8_t>(bytes[0]) % 3) {
                                          case 0:
                                            ManifestFromJson(j, "capture.json");
                                            break;
                                          case 1:
                                            ViewKeypointsFromJson(j, "keypoints.json");
                                            break;
                                          default:
                                            GroundTruthFromJson(j, "ground_truth.json");
                                        }
                                      }),
            3);
}

// A detection confidence outside [0, 1] names the view and keypoint.
TEST(CaptureJson, ConfidenceOutsideZeroToOneIsRefused) {
  nlohmann::json view = {{"camera", "cam0"},
                         {"keypoints", std::vector<std::vector<double>>(21, {1.0, 2.0})},
                         {"confidence", std::vector<double>(21, 0.5)}};
  const nlohmann::json good = {{"frame", "000000"}, {"views", {view}}};
  EXPECT_NO_THROW(ViewKeypointsFromJson(good, "d.json"));
  for (const double bad : {7.5, -3.0}) {
    nlohmann::json j = good;
    j["views"][0]["confidence"][6] = bad;
    const std::string error =
        testing::InputErrorOf([&] { ViewKeypointsFromJson(j, "d.json"); });
    EXPECT_NE(error.find("views[0].confidence[6]"), std::string::npos) << error;
    EXPECT_NE(error.find("[0, 1]"), std::string::npos) << error;
  }
  nlohmann::json unknown = good;
  unknown["views"][0]["score"] = 1;
  EXPECT_NE(testing::InputErrorOf([&] {
              ViewKeypointsFromJson(unknown, "d.json");
            }).find("views[0].score"),
            std::string::npos);
}

}  // namespace
}  // namespace handlabel
