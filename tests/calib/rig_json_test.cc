#include "calib/rig_json.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/errors.h"
#include "tests/calib/rig_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::ExpectRigsEqual;
using testing::RandomRig;
using testing::ScratchDir;

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Expects an InputError whose message contains every fragment.
template <typename F>
void ExpectInputError(F&& f, std::vector<std::string> fragments) {
  try {
    f();
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    for (const std::string& s : fragments) {
      EXPECT_NE(std::string(e.what()).find(s), std::string::npos)
          << "'" << s << "' not in: " << e.what();
    }
  }
}

TEST(RigJson, RoundTripsEveryModelExactly) {
  const Rig rig = RandomRig(9);
  const std::string path = ScratchDir() + "/rig.json";
  WriteRigJson(rig, path, {"camera:cam0"});
  RigFileInfo info;
  const Rig back = ReadRigJson(path, &info);
  ExpectRigsEqual(rig, back);
  EXPECT_EQ(info.world, "camera:cam0");
}

TEST(RigJson, StoresQuaternionAsXyzw) {
  Rig rig;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  rig.Add({"a", Camera::Pinhole(500, 500, 320, 240, 640, 480),
           Rigid3(q, Eigen::Vector3d(1, 2, 3))});
  const nlohmann::json j = RigToJson(rig);
  const auto& r = j["cameras"][0]["cam_from_world"]["rotation_xyzw"];
  EXPECT_DOUBLE_EQ(r[2].get<double>(), std::sin(0.25));
  EXPECT_DOUBLE_EQ(r[3].get<double>(), std::cos(0.25));
  EXPECT_EQ(j["cameras"][0]["model"], "PINHOLE");
}

TEST(RigJson, ErrorsNameFileAndField) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/bad.json";
  nlohmann::json good = RigToJson(RandomRig(2));

  nlohmann::json j = good;
  j["version"] = 7;
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); }, {path, "version", "7"});

  j = good;
  j["cameras"][1].erase("width");
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); },
                   {path, "cameras[1](cam1).width", "missing"});

  j = good;
  j["cameras"][0]["params"] = {1, 2};
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); }, {path, "params", "3 numbers"});

  j = good;
  j["cameras"][1]["cam_from_world"]["rotation_xyzw"] = {0, 0, 0, 2};
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); }, {"rotation_xyzw", "unit quaternion"});

  j = good;
  j["cameras"][1]["model"] = "KANNALA";
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); }, {path, "KANNALA", "OPENCV"});

  j = good;
  j["cameras"][1]["name"] = j["cameras"][0]["name"];
  WriteText(path, j.dump());
  ExpectInputError([&] { ReadRigJson(path); }, {"unique names", "cam0"});

  WriteText(path, "{\"format\": \"handlabel-rig\", ");
  ExpectInputError([&] { ReadRigJson(path); }, {path, "JSON"});

  ExpectInputError([&] { ReadRigJson(dir + "/absent.json"); },
                   {"absent.json", "cannot open"});
}

}  // namespace
}  // namespace handlabel
