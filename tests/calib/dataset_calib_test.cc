// Dataset calibration readers against fixtures written by
// tests/data/calib/make_dataset_fixtures.py from the documented layouts; truth.json
// holds what numpy computed for each camera.
#include "calib/dataset_calib.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/rig_io.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/calib";

nlohmann::json Truth(const std::string& format) {
  std::ifstream in(kData + "/truth.json");
  return nlohmann::json::parse(in).at(format);
}

void ExpectMatchesTruth(const Rig& rig, const nlohmann::json& truth, double tol) {
  ASSERT_EQ(rig.size(), truth.size());
  for (size_t i = 0; i < rig.size(); ++i) {
    const nlohmann::json& t = truth[i];
    EXPECT_EQ(rig[i].name, t["name"].get<std::string>());
    EXPECT_EQ(rig[i].camera.model(), CameraModelId::kPinhole);
    EXPECT_EQ(rig[i].camera.width(), t["width"].get<int>());
    EXPECT_EQ(rig[i].camera.height(), t["height"].get<int>());
    const std::vector<double> params = t["params"];
    EXPECT_THAT(
        Eigen::Map<const Eigen::Vector4d>(rig[i].camera.params().data()),
        testing::MatrixNear(Eigen::Map<const Eigen::Vector4d>(params.data()), tol));
    const std::vector<double> m = t["cam_from_world"];
    const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> expected(m.data());
    EXPECT_THAT(rig[i].cam_from_world.ToMatrix(), testing::MatrixNear(expected, tol))
        << rig[i].name;
  }
}

TEST(DatasetCalib, DexYcbFromExtrinsicsFileOrMeta) {
  const std::string extr =
      kData + "/dexycb/calibration/extrinsics_20200709-subject-01/extrinsics.yml";
  RigFileInfo info;
  ExpectMatchesTruth(ReadDatasetRig("dexycb", extr, &info), Truth("dexycb"), 1e-12);
  EXPECT_NE(info.world.find("836212060125"), std::string::npos);
  ExpectMatchesTruth(
      ReadRig({"dexycb", kData + "/dexycb/20200709-subject-01/20200709_141754/meta.yml"}),
      Truth("dexycb"), 1e-12);
}

TEST(DatasetCalib, Ho3dCalibrationFolder) {
  ExpectMatchesTruth(ReadDatasetRig("ho3d", kData + "/ho3d/calibration/ABF1/calibration"),
                     Truth("ho3d"), 1e-12);
}

TEST(DatasetCalib, OakInkPicklesThroughTheRestrictedReader) {
  const std::string folder = kData + "/oakink/image/anno/general_info";
  // float32 in the pickles: compare at float precision.
  ExpectMatchesTruth(ReadDatasetRig("oakink", folder), Truth("oakink"), 1e-5);
  const std::string one =
      folder + "/A01001_0001_0000__2021-09-26-19-59-58__0__00013__south_east.pkl";
  EXPECT_EQ(ReadDatasetRig("oakink", one).size(), 4u);
}

TEST(DatasetCalib, BrokenFilesNameFileAndField) {
  const std::string dir = testing::ScratchDir();
  fs::copy(kData + "/dexycb", dir + "/dexycb", fs::copy_options::recursive);
  const std::string extr =
      dir + "/dexycb/calibration/extrinsics_20200709-subject-01/extrinsics.yml";
  fs::remove(dir + "/dexycb/calibration/intrinsics/839512060362_640x480.yml");
  try {
    ReadDatasetRig("dexycb", extr);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("839512060362"), std::string::npos) << e.what();
  }
  std::ofstream(extr)
      << "extrinsics:\n  '836212060125': [1, 0, 0]\nmaster: '836212060125'\n";
  try {
    ReadDatasetRig("dexycb", extr);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("extrinsics.836212060125"), std::string::npos)
        << e.what();
  }
  fs::copy(kData + "/ho3d", dir + "/ho3d", fs::copy_options::recursive);
  const std::string ho3d = dir + "/ho3d/calibration/ABF1/calibration";
  std::ofstream(ho3d + "/cam_2_intrinsics.txt") << "fx:600, fy:601, ppx:320\n";
  try {
    ReadDatasetRig("ho3d", ho3d);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cam_2_intrinsics.txt"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("ppy"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadDatasetRig("oakink", dir), InputError);
}

}  // namespace
}  // namespace handlabel
