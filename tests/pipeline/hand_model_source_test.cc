#include "pipeline/hand_model_source.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>

#include <fstream>
#include <iterator>

#include "core/data_dir.h"
#include "core/errors.h"
#include "hand/hand_model_io.h"
#include "pipeline/train_config.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string ManoFixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/mano/" + name;
}

// The fixture model converted to the own format (which records side and tips).
std::string OwnModelFile(HandSide side) {
  HandModelLoadOptions options;
  options.tip_vertex_ids = std::array<int, 5>{1, 7, 5, 8, 6};
  options.side = side;
  const std::string path = testing::ScratchDir() + "/model.npz";
  SaveHandModel(LoadHandModel(ManoFixture("mano_smplx_right.npz"), options), path);
  return path;
}

TEST(HandModelSource, LoadsModelFilesGivenByFlag) {
  const std::string path = OwnModelFile(HandSide::kLeft);
  const ResolvedHandModel r = ResolveHandModel(path, HandSide::kLeft);
  EXPECT_EQ(r.source, path);
  EXPECT_EQ(r.model.side, HandSide::kLeft);
  EXPECT_EQ(r.model.num_vertices(), 12);
}

TEST(HandModelSource, RefusesAModelOfTheOtherSide) {
  const std::string path = OwnModelFile(HandSide::kRight);
  try {
    ResolveHandModel(path, HandSide::kLeft);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--hand-model"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a left hand model"), std::string::npos)
        << e.what();
  }
}

TEST(HandModelSource, BadModelFilesNameTheFileAndKey) {
  // A MANO-style pickle of 12 vertices has no default fingertips.
  try {
    ResolveHandModel(ManoFixture("mano_py2_right.pkl"), HandSide::kRight);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "tip_vertex_ids");
    EXPECT_NE(std::string(e.what()).find("mano_py2_right.pkl"), std::string::npos);
  }
}

TEST(HandModelSource, ShippedOpenHandIsTheDefaultForEachSide) {
  ::unsetenv("HANDLABEL_HAND_MODEL");
  const ResolvedHandModel right = ResolveHandModel("", HandSide::kRight);
  EXPECT_NE(right.source.find("models/open_hand_right.npz"), std::string::npos);
  EXPECT_EQ(right.model.side, HandSide::kRight);
  EXPECT_TRUE(right.note.empty());
  const ResolvedHandModel left = ResolveHandModel("", HandSide::kLeft);
  EXPECT_EQ(left.model.side, HandSide::kLeft);
}

TEST(HandModelSource, FlagBeatsEnvironmentAndCapsuleIsBuiltIn) {
  const std::string right =
      std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz";
  ::setenv("HANDLABEL_HAND_MODEL", "capsule", 1);
  EXPECT_EQ(ResolveHandModel("", HandSide::kRight).source, "builtin:capsule");
  EXPECT_EQ(ResolveHandModel(right, HandSide::kRight).source, right);
  ::unsetenv("HANDLABEL_HAND_MODEL");
  // A right-hand file when the left hand is asked for.
  try {
    ResolveHandModel(right, HandSide::kLeft);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "--hand-model");
    EXPECT_NE(std::string(e.what()).find("right hand"), std::string::npos);
  }
  EXPECT_THROW(ResolveHandModel("/nonexistent/model.npz", HandSide::kRight), InputError);
}

// Sets an environment variable for one scope (tests share the process environment).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

const std::string kShippedRight =
    std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz";

TEST(HandModelSource, ShippedModelsAreFoundRelativeToTheBinary) {
  // build/tests/pipeline_tests -> build/share/handlabel, which links to models/.
  ::unsetenv("HANDLABEL_DATA_DIR");
  const std::string path = ShippedModelPath("open_hand_right.npz");
  EXPECT_EQ(path.find(HANDLABEL_SOURCE_DIR "/models"), std::string::npos) << path;
  EXPECT_NE(path.find("/share/handlabel/models/open_hand_right.npz"), std::string::npos);
  EXPECT_EQ(FileBytes(path), FileBytes(kShippedRight));
}

TEST(HandModelSource, DataDirVariableNamesTheFolderOfModels) {
  const std::string dir = testing::ScratchDir();
  std::filesystem::create_directories(dir + "/models");
  std::filesystem::copy_file(kShippedRight, dir + "/models/open_hand_right.npz");
  ::unsetenv("HANDLABEL_HAND_MODEL");
  ScopedEnv data("HANDLABEL_DATA_DIR", dir);
  const ResolvedHandModel r = ResolveHandModel("", HandSide::kRight);
  EXPECT_EQ(r.source, dir + "/models/open_hand_right.npz");
  EXPECT_TRUE(r.note.empty());
}

TEST(HandModelSource, WithoutDataTheOpenHandIsBuiltInMemory) {
  ::unsetenv("HANDLABEL_HAND_MODEL");
  ScopedEnv data("HANDLABEL_DATA_DIR", testing::ScratchDir());  // no models/
  const ResolvedHandModel r = ResolveHandModel("", HandSide::kRight);
  EXPECT_EQ(r.source, "builtin:open_hand_right (built in memory)");
  EXPECT_NE(r.note.find("HANDLABEL_DATA_DIR"), std::string::npos) << r.note;
  // The shipped file is this build, saved; floating-point sums (PCA, regressor fit)
  // may differ in the last bits between compilers and BLAS builds.
  const HandModel shipped = LoadHandModel(kShippedRight);
  EXPECT_EQ(r.model.name, shipped.name);
  EXPECT_EQ(r.model.v_template, shipped.v_template);
  EXPECT_EQ(r.model.faces, shipped.faces);
  EXPECT_EQ(r.model.skinning_weights, shipped.skinning_weights);
  EXPECT_EQ(r.model.tip_vertex_ids, shipped.tip_vertex_ids);
  EXPECT_LT((r.model.shapedirs - shipped.shapedirs).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((Eigen::MatrixXd(r.model.joint_regressor) -
             Eigen::MatrixXd(shipped.joint_regressor))
                .cwiseAbs()
                .maxCoeff(),
            1e-9);
  EXPECT_LT((r.model.pose_pca_basis - shipped.pose_pca_basis).cwiseAbs().maxCoeff(),
            1e-9);
}

TEST(HandModelSource, TrainingUsesTheSameResolver) {
  ::unsetenv("HANDLABEL_HAND_MODEL");
  ::unsetenv("HANDLABEL_DATA_DIR");
  TrainConfig config;
  config.source_file = "train.yaml";
  std::string source;
  const HandModel shipped = LoadTrainingHandModel(config, &source);
  EXPECT_EQ(source, ResolveHandModel("", HandSide::kRight).source);
  // The same hand as the shipped file (what `train` used before the data folder).
  const HandModel expected = LoadHandModel(kShippedRight);
  EXPECT_EQ(FileBytes(source), FileBytes(kShippedRight));
  EXPECT_EQ(shipped.name, expected.name);
  EXPECT_EQ(shipped.v_template, expected.v_template);
  EXPECT_EQ(shipped.shapedirs, expected.shapedirs);
  EXPECT_EQ(shipped.faces, expected.faces);
  {
    ScopedEnv env("HANDLABEL_HAND_MODEL", "capsule");
    LoadTrainingHandModel(config, &source);
    EXPECT_EQ(source, "builtin:capsule");
  }
  // A given file trains with its own side; errors name the config file and field.
  config.hand_model = OwnModelFile(HandSide::kLeft);
  EXPECT_EQ(LoadTrainingHandModel(config, &source).side, HandSide::kLeft);
  config.hand_model = "/nonexistent/model.npz";
  const std::string error =
      testing::InputErrorOf([&] { LoadTrainingHandModel(config, &source); });
  EXPECT_NE(error.find("train.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("hand_model"), std::string::npos) << error;
}

}  // namespace
}  // namespace handlabel
