// Parity of the C++ POEM forward pass with an independent Python implementation
// (tests/network/poem_oracle.py, Debian python3-torch) on random weights written with
// torch.save. The oracle is required: if /usr/bin/python3 cannot import torch, the
// test fails (scripts/install-deps installs python3-torch).

#include <gtest/gtest.h>

#include <ATen/Parallel.h>

#include <cstdlib>
#include <fstream>

#include "network/poem_checkpoint.h"
#include "network/poem_import.h"
#include "network/poem_model.h"
#include "tests/network/tensor_bundle.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

struct OracleRun {
  std::map<std::string, torch::Tensor> weights, inputs, outputs;
  std::string dir;
};

OracleRun RunOracle(const PoemConfig& config, int batch, int seed) {
  OracleRun run;
  run.dir = testing::ScratchDir();
  const std::string cfg = run.dir + "/config.json";
  std::ofstream(cfg) << config.ToJson();
  const std::string script =
      std::string(HANDLABEL_SOURCE_DIR) + "/tests/network/poem_oracle.py";
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
  return run;
}

double MaxAbsDiff(const torch::Tensor& a, const torch::Tensor& b) {
  EXPECT_EQ(a.sizes(), b.sizes());
  if (a.sizes() != b.sizes()) return 1e30;
  return (a.to(torch::kFloat64) - b.to(torch::kFloat64)).abs().max().item<double>();
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
  for (int64_t l = 0; l < out.layer_coords.size(0); ++l) {
    EXPECT_LT(MaxAbsDiff(out.layer_coords[l], ref.at("layer_coords")[l]), 1e-4)
        << "decoder layer " << l;
  }

  // The same weights read from the torch.save file (released-checkpoint format) with
  // our own zip + restricted pickle readers give the same model.
  StateDictReport imported;
  PoemModel from_pth = ImportReleasedPoemCheckpoint(
      run.dir + "/PtEmbedMultiviewStereo.pth.tar", config, &imported);
  EXPECT_EQ(imported.ignored, (std::vector<std::string>{"mano_layer.th_faces"}));
  from_pth->eval();
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

}  // namespace
}  // namespace handlabel
