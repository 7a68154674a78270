#include "hand/hand_model_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "formats/npz.h"
#include "hand/hand_lbs.h"
#include "tests/hand/mano_sized_model.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string ManoFixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/mano/" + name;
}

const nlohmann::json& Expected() {
  static const nlohmann::json j = [] {
    std::ifstream in(ManoFixture("expected.json"));
    return nlohmann::json::parse(in);
  }();
  return j;
}

// Flattens nested JSON lists in row-major order.
void Flatten(const nlohmann::json& j, std::vector<double>* out) {
  if (j.is_array()) {
    for (const auto& x : j) Flatten(x, out);
  } else {
    out->push_back(j.get<double>());
  }
}

Eigen::MatrixXd JsonMatrix(const nlohmann::json& j, Eigen::Index rows,
                           Eigen::Index cols) {
  std::vector<double> v;
  Flatten(j, &v);
  EXPECT_EQ(static_cast<Eigen::Index>(v.size()), rows * cols);
  return Eigen::Map<
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v.data(),
                                                                              rows, cols);
}

HandModelLoadOptions FixtureOptions() {
  HandModelLoadOptions options;
  std::array<int, 5> tips;
  for (int t = 0; t < 5; ++t) tips[t] = Expected()["tip_vertex_ids"][t];
  options.tip_vertex_ids = tips;
  return options;
}

// Exact equality with the arrays the fixture script wrote.
void ExpectFixtureArrays(const HandModel& m) {
  const nlohmann::json& e = Expected()["model"];
  const Eigen::Index nv = 12;
  ASSERT_EQ(m.num_vertices(), nv);
  EXPECT_EQ(Eigen::MatrixXd(m.v_template), JsonMatrix(e["v_template"], nv, 3));
  EXPECT_EQ(Eigen::MatrixXd(m.faces.cast<double>()), JsonMatrix(e["f"], 16, 3));
  EXPECT_EQ(m.shapedirs, JsonMatrix(e["shapedirs"], 3 * nv, 10));
  EXPECT_EQ(m.posedirs, JsonMatrix(e["posedirs"], 3 * nv, 135));
  EXPECT_EQ(Eigen::MatrixXd(m.joint_regressor), JsonMatrix(e["J_regressor"], 16, nv));
  EXPECT_EQ(Eigen::MatrixXd(m.skinning_weights), JsonMatrix(e["weights"], nv, 16));
  EXPECT_EQ(m.pose_pca_basis, JsonMatrix(e["hands_components"], 45, 45));
  EXPECT_EQ(Eigen::MatrixXd(m.pose_mean), JsonMatrix(e["hands_mean"], 45, 1));
  for (int j = 0; j < kNumHandJoints; ++j)
    EXPECT_EQ(m.parents[j], Expected()["parents"][j]);
  EXPECT_EQ(m.side, HandSide::kRight);
}

// make_mano_fixtures.py's NumPy LBS on the same arrays.
void ExpectNumpyLbs(const HandModel& m) {
  for (const nlohmann::json& c : Expected()["cases"]) {
    HandParams p;
    p.global_orient = JsonMatrix(c["global_orient"], 3, 1);
    p.hand_pose = JsonMatrix(c["hand_pose"], 45, 1);
    p.betas = JsonMatrix(c["betas"], 10, 1);
    p.transl = JsonMatrix(c["transl"], 3, 1);
    const HandMesh mesh = PoseHand(m, p);
    EXPECT_THAT(mesh.vertices,
                testing::MatrixNear(JsonMatrix(c["vertices"], 12, 3), 1e-9));
    EXPECT_THAT(mesh.joints, testing::MatrixNear(JsonMatrix(c["joints"], 16, 3), 1e-9));
    EXPECT_THAT(mesh.keypoints,
                testing::MatrixNear(JsonMatrix(c["keypoints"], 21, 3), 1e-9));
  }
}

struct FormatCase {
  const char* file;
  HandModelFormat format;
};

class EveryFormat : public ::testing::TestWithParam<FormatCase> {};

TEST_P(EveryFormat, LoadsExactlyTheWrittenArraysAndMatchesNumpyLbs) {
  const LoadedHandModel loaded =
      LoadHandModelFile(ManoFixture(GetParam().file), FixtureOptions());
  EXPECT_EQ(loaded.format, GetParam().format);
  ExpectFixtureArrays(loaded.model);
  ExpectNumpyLbs(loaded.model);
}

TEST_P(EveryFormat, ConvertsToTheOwnFormatWithoutLoss) {
  const HandModel m = LoadHandModel(ManoFixture(GetParam().file), FixtureOptions());
  const std::string path = testing::ScratchDir() + "/model.npz";
  SaveHandModel(m, path);
  const LoadedHandModel back = LoadHandModelFile(path);  // needs no options
  EXPECT_EQ(back.format, HandModelFormat::kHandlabelNpz);
  ExpectFixtureArrays(back.model);
  EXPECT_EQ(back.model.tip_vertex_ids, m.tip_vertex_ids);
  EXPECT_EQ(back.model.name, m.name);
  ExpectNumpyLbs(back.model);
}

INSTANTIATE_TEST_SUITE_P(
    Files, EveryFormat,
    ::testing::Values(FormatCase{"mano_py2_right.pkl", HandModelFormat::kManoPickle},
                      FormatCase{"mano_resaved_p4_right.pkl", HandModelFormat::kPickle},
                      FormatCase{"mano_resaved_p5_right.pkl", HandModelFormat::kPickle},
                      FormatCase{"mano_smplx_right.npz", HandModelFormat::kSmplxNpz},
                      FormatCase{"mano_smplx_object_right.npz",
                                 HandModelFormat::kSmplxNpz}));

TEST(HandModelIo, SideComesFromTheFileNameOrTheOptions) {
  const std::string dir = testing::ScratchDir();
  namespace fs = std::filesystem;
  fs::copy_file(ManoFixture("mano_py2_right.pkl"), dir + "/MANO_LEFT.pkl");
  fs::copy_file(ManoFixture("mano_py2_right.pkl"), dir + "/hand.pkl");
  EXPECT_EQ(LoadHandModel(dir + "/MANO_LEFT.pkl", FixtureOptions()).side,
            HandSide::kLeft);
  EXPECT_EQ(LoadHandModel(dir + "/MANO_LEFT.pkl", FixtureOptions()).name, "MANO_LEFT");
  try {
    LoadHandModel(dir + "/hand.pkl", FixtureOptions());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "side");
    EXPECT_NE(std::string(e.what()).find("hand.pkl"), std::string::npos);
  }
  HandModelLoadOptions options = FixtureOptions();
  options.side = HandSide::kLeft;
  EXPECT_EQ(LoadHandModel(dir + "/hand.pkl", options).side, HandSide::kLeft);
  // The side survives the own format.
  SaveHandModel(LoadHandModel(dir + "/hand.pkl", options), dir + "/own.npz");
  EXPECT_EQ(LoadHandModel(dir + "/own.npz").side, HandSide::kLeft);
}

TEST(HandModelIo, NonManoSizedModelsNeedFingertipIds) {
  try {
    LoadHandModel(ManoFixture("mano_py2_right.pkl"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "tip_vertex_ids");
  }
}

// The smplx npz fixture with one entry replaced, added, or removed (no value).
std::string NpzWith(const std::string& key, const std::optional<NdArray>& value) {
  NamedArrays arrays = ReadNpzFile(ManoFixture("mano_smplx_right.npz"));
  bool found = false;
  for (auto it = arrays.begin(); it != arrays.end(); ++it) {
    if (it->first == key) {
      found = true;
      if (value) {
        it->second = *value;
      } else {
        arrays.erase(it);
      }
      break;
    }
  }
  if (!found && value) arrays.emplace_back(key, *value);
  const std::string path = testing::ScratchDir() + "/broken_right.npz";
  WriteNpzFile(path, arrays);
  return path;
}

std::string LoadError(const std::string& path) {
  try {
    LoadHandModel(path, FixtureOptions());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HandModelIo, BadFilesGiveErrorsNamingFileAndKey) {
  const double x[6] = {1, 2, 3, 4, 5, 6};
  std::string path = NpzWith("shapedirs", NdArray::FromDoubles({2, 3}, x));
  std::string error = LoadError(path);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("'shapedirs'"), std::string::npos) << error;
  EXPECT_NE(error.find("(12, 3, N)"), std::string::npos) << error;

  error = LoadError(NpzWith("weights", std::nullopt));
  EXPECT_NE(error.find("'weights'"), std::string::npos) << error;
  EXPECT_NE(error.find("missing"), std::string::npos) << error;

  std::vector<int64_t> faces(48, 0);
  faces[7] = 99;
  error = LoadError(NpzWith("f", NdArray::FromInt64s({16, 3}, faces.data())));
  EXPECT_NE(error.find("'f'"), std::string::npos) << error;
  EXPECT_NE(error.find("99"), std::string::npos) << error;

  std::vector<double> nan_template(36, 0.0);
  nan_template[4] = std::nan("");
  error = LoadError(
      NpzWith("v_template", NdArray::FromDoubles({12, 3}, nan_template.data())));
  EXPECT_NE(error.find("finite"), std::string::npos) << error;

  // Skinning styles MANO's code does not implement are refused, not approximated.
  error = LoadError(NpzWith("bs_style", NdArray::FromText("dqs")));
  EXPECT_NE(error.find("'bs_style'"), std::string::npos) << error;

  std::vector<int64_t> kintree(32, 0);
  kintree[5] = 77;
  error =
      LoadError(NpzWith("kintree_table", NdArray::FromInt64s({2, 16}, kintree.data())));
  EXPECT_NE(error.find("'kintree_table'"), std::string::npos) << error;

  // A pickle with a hostile global fails in the pickle reader, naming the file.
  path = testing::ScratchDir() + "/evil_right.pkl";
  std::ofstream(path) << "cos\nsystem\n(S'echo hacked'\ntR.";
  error = LoadError(path);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("os.system"), std::string::npos) << error;

  // A truncated official-style pickle.
  std::ifstream in(ManoFixture("mano_py2_right.pkl"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)),
                    std::istreambuf_iterator<char>());
  path = testing::ScratchDir() + "/cut_right.pkl";
  std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(LoadError(path).find("truncated"), std::string::npos) << LoadError(path);
}

// A MANO-sized file in the official layout (written by the C++ test writer, since MANO
// cannot be committed): loads without options, with manopth's fingertips, exactly.
TEST(HandModelIo, ManoSizedOfficialLayoutLoadsExactlyWithDefaults) {
  const HandModel m = testing::RandomManoSizedModel(testing::TestSeed());
  const std::string path = testing::ScratchDir() + "/MANO_RIGHT.pkl";
  std::ofstream(path, std::ios::binary) << testing::ManoStylePickle(m);
  const LoadedHandModel loaded = LoadHandModelFile(path);
  EXPECT_EQ(loaded.format, HandModelFormat::kManoPickle);
  const HandModel& l = loaded.model;
  EXPECT_EQ(l.side, HandSide::kRight);
  EXPECT_EQ(l.tip_vertex_ids, (std::array<int, 5>{745, 317, 444, 556, 673}));
  EXPECT_EQ(Eigen::MatrixXd(l.v_template), Eigen::MatrixXd(m.v_template));
  EXPECT_EQ(l.faces, m.faces);
  EXPECT_EQ(l.shapedirs, m.shapedirs);
  EXPECT_EQ(l.posedirs, m.posedirs);
  EXPECT_EQ(Eigen::MatrixXd(l.joint_regressor), Eigen::MatrixXd(m.joint_regressor));
  EXPECT_EQ(Eigen::MatrixXd(l.skinning_weights), Eigen::MatrixXd(m.skinning_weights));
  EXPECT_EQ(l.pose_pca_basis, m.pose_pca_basis);
  EXPECT_EQ(l.pose_mean, m.pose_mean);
  EXPECT_EQ(l.parents, m.parents);
}

}  // namespace
}  // namespace handlabel
