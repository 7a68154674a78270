// Camera names in captures (issue 46): a camera named "{frame}x" expanded inside file
// patterns (two cameras shared one path and one camera's images were overwritten, exit
// 0), and names with spaces or newlines were accepted but the COLMAP text model that
// `capture init` writes read back broken. Such names are refused where a capture's
// cameras are named (capture init, capture.json), and patterns expand in one pass.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "capture/capture_format.h"
#include "capture/capture_import.h"
#include "core/errors.h"
#include "tests/capture/capture_import_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::InputErrorOf;

TEST(CameraNames, NamesThatPatternsFoldersOrColmapCannotHoldAreRefusedAtInit) {
  for (const std::string name : {"{frame}", "cam{camera}", "cam 1", "cam\n2", "cam\t3",
                                 "a/b", "a\\b", "..", "."}) {
    Rig rig = testing::SmallRig(1);
    rig.Add({name, rig[0].camera, Rigid3()});
    CaptureInitOptions init;
    init.rig_source = "json:rig.json";
    const std::string dir = testing::ScratchDir() + "/capture";
    const std::string error = InputErrorOf([&] { InitCapture(rig, {}, dir, init); });
    EXPECT_THAT(error, HasSubstr("json:rig.json: field 'cameras[1] name': expected a "
                                 "camera name usable as a folder name, in file patterns "
                                 "and in COLMAP's text model"))
        << name;
    EXPECT_THAT(error, HasSubstr("got " + nlohmann::json(name).dump())) << name;
    EXPECT_FALSE(std::filesystem::exists(dir + "/capture.json")) << name;
  }
  Rig rig = testing::SmallRig(1);
  rig.Add({"cam-2_left.B", rig[0].camera, Rigid3()});  // punctuation is fine
  EXPECT_NO_THROW(InitCapture(rig, {}, testing::ScratchDir() + "/ok", {}));
}

TEST(CameraNames, CaptureJsonWithSuchANameIsRefused) {
  CaptureManifest manifest;
  manifest.cameras = {"cam0", "cam{frame}"};
  manifest.frames = {"000000"};
  manifest.files["image"] = "images/{camera}/{frame}.png";
  EXPECT_THAT(InputErrorOf([&] { ManifestFromJson(ManifestToJson(manifest), "c.json"); }),
              HasSubstr("c.json: field 'cameras[1]'"));
}

TEST(CameraNames, PatternsExpandInOnePass) {
  EXPECT_EQ(ExpandPattern("images/{camera}/{frame}.png", "{frame}", "000007"),
            "images/{frame}/000007.png");
  EXPECT_EQ(ExpandPattern("{frame}{camera}{frame}", "c", "{camera}"),
            "{camera}c{camera}");
  EXPECT_EQ(ExpandPattern("{cam}{camera", "c", "f"), "{cam}{camera");
}

}  // namespace
}  // namespace handlabel
