// Parity of the C++ POEM forward pass with an independent Python implementation
// (tests/network/poem/poem_oracle.py, Debian python3-torch) on random weights written
// with torch.save. The oracle is required: if /usr/bin/python3 cannot import torch, the
// test fails (scripts/install-deps installs python3-torch).

#include <gtest/gtest.h>

#include <ATen/Parallel.h>

#include <cstdlib>
#include <fstream>

#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_import.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"
#include "tests/network/poem/poem_test_util.h"
#include "tests/network/poem/tensor_bundle.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::ExpectDecoderCoordsNear;
using testing::MaxAbsDiff;

struct OracleRun {
  std::map<std::string, torch::Tensor> weights, inputs, outputs, targets, losses;
  std::string dir;
};

OracleRun RunOracle(const PoemConfig& config, int batch, int seed) {
  OracleRun run;
  run.dir = testing::ScratchDir();
  const std::string cfg = run.dir + "/config.json";
  std::ofstream(cfg) << config.ToJson();
  const std::string script =
      std::string(HANDLABEL_SOURCE_DIR) + "/tests/network/poem/poem_oracle.py";
  const std::string cmd = "/usr/bin/python3 " + script + " --config " + cfg + " --out " +
                          run.dir + " --seed " + std::to_string(seed) + " --batch " +
                          std::to_string(batch) + " > " + run.dir + "/oracle.log 2>&1";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    std::ifstream log(run.dir + "/oracle.log");
    std::stringstream ss;
    ss << log.rdbuf();
    ADD_FAILURE() << "the Python oracle failed (needs /usr/bin/python3 with torch, "
                     "Debian python3-torch):\n"
                  << ss.str();
    return run;
  }
  run.weights = testing::ReadTensorBundle(run.dir + "/weights");
  run.inputs = testing::ReadTensorBundle(run.dir + "/inputs");
  run.outputs = testing::ReadTensorBundle(run.dir + "/outputs");
  run.targets = testing::ReadTensorBundle(run.dir + "/targets");
  run.losses = testing::ReadTensorBundle(run.dir + "/losses");
  return run;
}

// Returns the oracle's folder (with its torch.save checkpoint) for further checks.
std::string ExpectParity(const PoemConfig& config, int batch, int seed) {
  at::set_num_threads(1);  // as the oracle
  OracleRun run = RunOracle(config, batch, seed);
  if (run.outputs.empty()) return "";
  PoemModel model(config);
  const StateDictReport report =
      LoadPoemStateDict(model, run.weights, run.dir + "/weights", {"mano_layer."});
  EXPECT_EQ(report.ignored, (std::vector<std::string>{"mano_layer.th_faces"}));
  model->eval();
  FoldNormsForInference(*model);  // the predictor's path
  torch::NoGradGuard no_grad;
  PoemBatch b;
  b.images = run.inputs.at("images");
  b.intrinsics = run.inputs.at("intrinsics");
  b.master_from_cam = run.inputs.at("master_from_cam");
  const PoemOutputs out = model->forward(b);
  const auto& ref = run.outputs;

  EXPECT_LT(MaxAbsDiff(out.joints_2d, ref.at("joints_2d")), 1e-4);
  EXPECT_LT(MaxAbsDiff(out.triangulated_joints, ref.at("triangulated_joints")), 1e-4);
  EXPECT_LT(MaxAbsDiff(out.initial_mesh, ref.at("initial_mesh")), 1e-4);
  EXPECT_LT(MaxAbsDiff(out.ball_center, ref.at("ball_center")), 1e-5);
  // The same deterministic selection on both sides.
  EXPECT_TRUE(torch::equal(out.point_index, ref.at("point_index")));
  for (int i = 0; i < batch; ++i) {
    EXPECT_EQ(out.points_inside_ball[i], ref.at("points_inside_ball")[i].item<int64_t>());
  }
  EXPECT_LT(MaxAbsDiff(out.sampled_points, ref.at("sampled_points")), 1e-6);
  ExpectDecoderCoordsNear(out.layer_coords, ref.at("layer_coords"), 1e-5);

  // The training losses agree with the oracle's implementation of the reference's.
  PoemTargets t;
  t.joints_3d = run.targets.at("joints_3d");
  t.vertices_3d = run.targets.at("vertices_3d");
  t.joints_2d = run.targets.at("joints_2d");
  const PoemLoss loss = ComputePoemLoss(out, b, t, run.targets.at("regressor"));
  auto expect_term = [&](const std::string& name, const torch::Tensor& value) {
    const double want = run.losses.at(name).item<double>();
    EXPECT_NEAR(value.item<double>(), want, 1e-4 * std::max(1.0, std::abs(want))) << name;
  };
  expect_term("total", loss.total);
  for (const auto& [name, value] : loss.terms) expect_term(name, value);
  EXPECT_EQ(loss.terms.size() + 1, run.losses.size());

  // The same weights read from the torch.save file (released-checkpoint format) with
  // our own zip + restricted pickle readers give the same model.
  StateDictReport imported;
  PoemModel from_pth = ImportReleasedPoemCheckpoint(
      run.dir + "/PtEmbedMultiviewStereo.pth.tar", config, &imported);
  EXPECT_EQ(imported.ignored, (std::vector<std::string>{"mano_layer.th_faces"}));
  from_pth->eval();
  FoldNormsForInference(*from_pth);
  EXPECT_TRUE(torch::equal(from_pth->forward(b).layer_coords, out.layer_coords));
  return run.dir;
}

TEST(PoemParity, TinyThreeViewsMatchesPythonOracle) {
  ExpectParity(TinyPoemConfig(3), 2, 1);
}

TEST(PoemParity, TinyResNet34FourViewsMatchesPythonOracle) {
  PoemConfig c = TinyPoemConfig(4);
  c.backbone = "resnet34";
  c.num_decoder_blocks = 3;
  c.position_range = {-1.0, -1.0, 0.0, 1.0, 1.0, 1.5};  // OakInk-like, depth from 0
  ExpectParity(c, 1, 2);
}

// The full released architecture: the oracle's key set and shapes (written from the
// specification) equal the C++ model's (ResNet34, 6 blocks; views do not change keys).
TEST(PoemParity, ReleasedStateDictKeysAndShapesMatchOracle) {
  const std::string dir = testing::ScratchDir();
  std::ofstream(dir + "/config.json")
      << ReleasedPoemConfig(PoemDataset::kDexYCB).ToJson();
  const std::string cmd = "/usr/bin/python3 " + std::string(HANDLABEL_SOURCE_DIR) +
                          "/tests/network/poem/poem_oracle.py --shapes-only --config " +
                          dir + "/config.json --out " + dir + " > " + dir +
                          "/oracle.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0)
      << "the Python oracle failed (needs /usr/bin/python3 with torch)";
  std::ifstream f(dir + "/shapes.json");
  const nlohmann::json shapes = nlohmann::json::parse(f);
  PoemModel model(ReleasedPoemConfig(PoemDataset::kDexYCB));
  const auto sd = PoemStateDict(model);
  int64_t parameters = 0;
  for (const auto& [key, shape] : shapes.items()) {
    if (key.rfind("mano_layer.", 0) == 0) continue;
    ASSERT_TRUE(sd.count(key)) << "C++ model lacks " << key;
    EXPECT_EQ(sd.at(key).sizes().vec(), shape.get<std::vector<int64_t>>()) << key;
  }
  for (const auto& [key, tensor] : sd) {
    EXPECT_TRUE(shapes.contains(key)) << "oracle lacks " << key;
  }
  for (const auto& p : model->parameters()) parameters += p.numel();
  RecordProperty("released_parameters", std::to_string(parameters));
}

}  // namespace
}  // namespace handlabel
