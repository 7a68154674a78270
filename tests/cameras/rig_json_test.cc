#include "cameras/rig_json.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "core/errors.h"
#include "tests/cameras/rig_fixture.h"
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

// Numbers that used to pass silently: a width that wraps to 640 in 32 bits, sizes of
// 2^31 and 2^40, focal 1e300, cx -1e6, translation 1e308, unknown and repeated keys.
TEST(RigJson, RefusesImplausibleNumbersAndUnknownOrRepeatedKeys) {
  const std::string path = ScratchDir() + "/bad.json";
  const nlohmann::json good = RigToJson(RandomRig(2));
  const auto expect = [&](const std::function<void(nlohmann::json&)>& edit,
                          std::vector<std::string> fragments) {
    nlohmann::json j = good;
    edit(j);
    WriteText(path, j.dump());
    fragments.push_back(path);
    ExpectInputError([&] { ReadRigJson(path); }, fragments);
  };
  expect([](auto& j) { j["cameras"][0]["width"] = 4294967936ull; },
         {"cameras[0](cam0).width", "4294967936", "[1, 65536]"});
  expect([](auto& j) { j["cameras"][0]["width"] = 2147483648ll; },
         {"width", "2147483648"});
  expect([](auto& j) { j["cameras"][1]["height"] = 1099511627776ll; },
         {"cameras[1](cam1).height", "1099511627776"});
  expect([](auto& j) { j["cameras"][0]["params"][0] = 1e300; },
         {"cameras[0](cam0).params (focal length)", "1e+300"});
  expect([](auto& j) { j["cameras"][1]["params"][2] = -1e6; },
         {"cameras[1](cam1).params (cx)", "-1e+06"});
  expect([](auto& j) { j["cameras"][0]["cam_from_world"]["translation"][1] = 1e308; },
         {"cameras[0](cam0).cam_from_world.translation", "1e+308"});
  expect([](auto& j) { j["cameras"][1]["focal"] = 500; },
         {"cameras[1].focal", "unknown key", "params"});
  expect([](auto& j) { j["camera"] = nlohmann::json::array(); },
         {"camera", "unknown key", "cameras"});
  // A repeated key: nlohmann would keep the last, so it is written by hand.
  std::string text = good.dump();
  text.insert(text.find("\"version\""), "\"version\":1,");
  WriteText(path, text);
  ExpectInputError([&] { ReadRigJson(path); }, {path, "version", "each key once"});
}

}  // namespace
}  // namespace handlabel
