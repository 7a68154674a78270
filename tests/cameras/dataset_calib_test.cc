// Dataset calibration readers against fixtures written by
// tests/data/calib/make_dataset_fixtures.py from the documented layouts; truth.json
// holds what numpy computed for each camera.
#include "cameras/dataset_calib.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cameras/rig_io.h"
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

// The fixture's cam_orders.txt is 1 3 2 4 0: camera ABF1<order[i]> takes trans_<i> and
// cam_<i>_intrinsics (HO3D's viewer). Reading trans_<order[i]> instead (the pairing
// this reader had) gives four wrong cameras and fails here.
TEST(DatasetCalib, Ho3dCalibrationFolderPairsFilesByPositionInCamOrders) {
  const nlohmann::json truth = Truth("ho3d");
  ASSERT_EQ(truth[0]["name"], "ABF11");  // the fixture's order is not the identity
  ExpectMatchesTruth(ReadDatasetRig("ho3d", kData + "/ho3d/calibration/ABF1/calibration"),
                     truth, 1e-12);
}

// cam_orders.txt as np.loadtxt reads it: whitespace (one line or one per line, np.savetxt
// style), not commas; every index once.
TEST(DatasetCalib, Ho3dCamOrdersAsNumpyReadsThem) {
  const std::string dir = testing::ScratchDir();
  fs::copy(kData + "/ho3d", dir + "/ho3d", fs::copy_options::recursive);
  const std::string ho3d = dir + "/ho3d/calibration/ABF1/calibration";
  std::ofstream(ho3d + "/cam_orders.txt") << "1.000000000000000000e+00\n3\n2\n4\n0\n";
  ExpectMatchesTruth(ReadDatasetRig("ho3d", ho3d), Truth("ho3d"), 1e-12);
  const auto error_of = [&](const std::string& text) {
    std::ofstream(ho3d + "/cam_orders.txt") << text;
    try {
      ReadDatasetRig("ho3d", ho3d);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error_of("1,3,2,4,0\n"),
              ::testing::AllOf(::testing::HasSubstr("cam_orders.txt"),
                               ::testing::HasSubstr("np.loadtxt")));
  EXPECT_THAT(error_of("1 3 1 4 0\n"), ::testing::HasSubstr("1 twice"));
  // As many indices as cameras (trans_<i>.txt): 4 of 5 made a 4-camera rig silently.
  EXPECT_THAT(error_of("1 3 2 4\n"),
              ::testing::HasSubstr("cam_orders.txt: field '(camera order)': expected one "
                                   "camera index per trans_<i>.txt beside it (5), got 4 "
                                   "indices"));
  EXPECT_THAT(error_of("1 3 2 4 0 5\n"), ::testing::HasSubstr("got 6 indices"));
}

// DexYCB: the extrinsics file alone lists the apriltag entry (not a camera), and a
// second intrinsics size beside 640x480 is not taken; two sizes without 640x480 are an
// error, one other size is taken as it is.
TEST(DatasetCalib, DexYcbSkipsTheTagAndTakes640x480) {
  const std::string dir = testing::ScratchDir();
  fs::copy(kData + "/dexycb", dir + "/dexycb", fs::copy_options::recursive);
  const std::string extr =
      dir + "/dexycb/calibration/extrinsics_20200709-subject-01/extrinsics.yml";
  const std::string intrinsics = dir + "/dexycb/calibration/intrinsics/836212060125";
  const Rig rig = ReadDatasetRig("dexycb", extr);
  ASSERT_EQ(rig.size(), 3u);
  EXPECT_LT(rig.IndexOf("apriltag"), 0);
  EXPECT_EQ(rig[0].camera.width(), 640);
  fs::rename(intrinsics + "_640x480.yml", intrinsics + "_320x240.yml");
  try {
    ReadDatasetRig("dexycb", extr);
    FAIL() << "two sizes without 640x480";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("836212060125_1280x720.yml, "
                                               "836212060125_320x240.yml"));
  }
  fs::remove(intrinsics + "_1280x720.yml");
  EXPECT_EQ(ReadDatasetRig("dexycb", extr)[0].camera.width(), 320);
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
  fs::remove(dir + "/dexycb/calibration/intrinsics/839512060362_1280x720.yml");
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
