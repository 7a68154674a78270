// Forward-pass cost of the hand model: reference PoseHand and HandEvaluator with
// doubles, core Dual and ceres::Jet, on a random MANO-sized model (778 vertices, 1538
// faces, 10 betas, dense pose blend shapes). Timings do not depend on the values, so
// random arrays stand in for MANO (which cannot ship).
//
//   ./build/bench/hand_model_bench [--benchmark_filter=Keypoints]
// The argument of each benchmark is the number of non-zero skinning weights per vertex
// (MANO-like sparse ~4, or fully dense 16).

#include <benchmark/benchmark.h>
#include <ceres/jet.h>

#include <random>
#include <type_traits>
#include <vector>

#include "geometry/dual.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_evaluator.h"
#include "hand/hand_lbs.h"

namespace handlabel {
namespace {

constexpr int kNumParams = 3 + 45 + 10 + 3;

HandModel RandomManoSizedModel(int weights_per_vertex) {
  constexpr int kVerts = 778, kFaces = 1538, kBetas = 10;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> vertex(0, kVerts - 1);
  HandModel model;
  model.name = "random_mano_sized";
  model.v_template.resize(kVerts, 3);
  for (int v = 0; v < kVerts; ++v) {
    for (int c = 0; c < 3; ++c) model.v_template(v, c) = 0.05 * g(rng);
  }
  model.faces.resize(kFaces, 3);
  for (int f = 0; f < kFaces; ++f) {
    model.faces.row(f) << vertex(rng), vertex(rng), vertex(rng);
  }
  model.shapedirs =
      0.01 * Eigen::MatrixXd::NullaryExpr(3 * kVerts, kBetas, [&]() { return g(rng); });
  model.posedirs =
      0.01 * Eigen::MatrixXd::NullaryExpr(3 * kVerts, 135, [&]() { return g(rng); });
  std::vector<Eigen::Triplet<double>> reg;
  for (int j = 0; j < kNumHandJoints; ++j) {
    for (int k = 0; k < 20; ++k) reg.emplace_back(j, vertex(rng), 1.0 / 20);
  }
  model.joint_regressor.resize(kNumHandJoints, kVerts);
  model.joint_regressor.setFromTriplets(reg.begin(), reg.end());
  model.skinning_weights.setZero(kVerts, kNumHandJoints);
  for (int v = 0; v < kVerts; ++v) {
    const int first = v % kNumHandJoints;
    for (int k = 0; k < weights_per_vertex; ++k) {
      model.skinning_weights(v, (first + k) % kNumHandJoints) = 1.0 / weights_per_vertex;
    }
  }
  model.tip_vertex_ids = {745, 317, 444, 556, 673};
  model.pose_pca_basis =
      0.3 * Eigen::MatrixXd::NullaryExpr(45, 45, [&]() { return g(rng); });
  model.pose_mean = Eigen::VectorXd::Zero(45);
  model.Check("bench");
  return model;
}

std::vector<double> RandomParams(int n) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g(0.0, 0.5);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

template <int N>
std::vector<Dual<N>> SeedDual(const std::vector<double>& x) {
  std::vector<Dual<N>> out(x.size());
  for (size_t i = 0; i < x.size(); ++i) out[i] = Dual<N>(x[i], static_cast<int>(i));
  return out;
}
template <int N>
std::vector<ceres::Jet<double, N>> SeedJet(const std::vector<double>& x) {
  std::vector<ceres::Jet<double, N>> out(x.size());
  for (size_t i = 0; i < x.size(); ++i) out[i] = ceres::Jet<double, N>(x[i], i);
  return out;
}

template <typename T>
std::vector<T> SeedAny(const std::vector<double>& x) {
  if constexpr (std::is_same_v<T, double>) {
    return x;
  } else if constexpr (std::is_same_v<T, Dual<kNumParams>>) {
    return SeedDual<kNumParams>(x);
  } else {
    return SeedJet<kNumParams>(x);
  }
}

void BM_PoseHandReference(benchmark::State& state) {
  const HandModel model = RandomManoSizedModel(static_cast<int>(state.range(0)));
  const std::vector<double> x = RandomParams(kNumParams);
  HandParams params;
  params.global_orient = Eigen::Map<const Eigen::Vector3d>(x.data());
  params.hand_pose =
      Eigen::Map<const Eigen::Matrix<double, kNumPoseParams, 1>>(x.data() + 3);
  params.betas = Eigen::Map<const Eigen::VectorXd>(x.data() + 48, 10);
  params.transl = Eigen::Map<const Eigen::Vector3d>(x.data() + 58);
  for (auto _ : state) benchmark::DoNotOptimize(PoseHand(model, params));
}

template <typename T>
void BM_Keypoints(benchmark::State& state) {
  const HandEvaluator evaluator(RandomManoSizedModel(static_cast<int>(state.range(0))));
  const std::vector<T> x = SeedAny<T>(RandomParams(kNumParams));
  std::vector<T> out(63);
  for (auto _ : state) {
    evaluator.Keypoints(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, out.data());
    benchmark::DoNotOptimize(out.data());
  }
}

template <typename T>
void BM_AllVertices(benchmark::State& state) {
  const HandEvaluator evaluator(RandomManoSizedModel(static_cast<int>(state.range(0))));
  const std::vector<T> x = SeedAny<T>(RandomParams(kNumParams));
  std::vector<T> out(3 * evaluator.num_vertices());
  for (auto _ : state) {
    evaluator.AllVertices(x.data(), x.data() + 3, x.data() + 48, x.data() + 58,
                          out.data());
    benchmark::DoNotOptimize(out.data());
  }
}

// Keypoints with the pose as 12 PCA coefficients: 3 + 12 + 10 + 3 = 28 derivatives.
void BM_KeypointsPca12Jet(benchmark::State& state) {
  HandEvaluatorOptions options;
  options.num_pca_comps = 12;
  const HandEvaluator evaluator(RandomManoSizedModel(static_cast<int>(state.range(0))),
                                options);
  const std::vector<ceres::Jet<double, 28>> x = SeedJet<28>(RandomParams(28));
  std::vector<ceres::Jet<double, 28>> out(63);
  for (auto _ : state) {
    evaluator.Keypoints(x.data(), x.data() + 3, x.data() + 15, x.data() + 25, out.data());
    benchmark::DoNotOptimize(out.data());
  }
}

// Analytic keypoint Jacobian (doubles), 63 x 61.
void BM_KeypointsAnalyticJacobian(benchmark::State& state) {
  const HandEvaluator evaluator(RandomManoSizedModel(static_cast<int>(state.range(0))));
  const std::vector<double> x = RandomParams(kNumParams);
  std::vector<double> keypoints(63), jacobian(63 * kNumParams);
  for (auto _ : state) {
    evaluator.KeypointsAndJacobian(x.data(), x.data() + 3, x.data() + 48, x.data() + 58,
                                   keypoints.data(), jacobian.data());
    benchmark::DoNotOptimize(jacobian.data());
  }
}

// Anatomical angles + limit residuals of all 15 joints with Jets (fitting's prior).
void BM_AnatomyResidualsJet(benchmark::State& state) {
  // Identity frames: the cost does not depend on the frames' values.
  std::vector<double> x = RandomParams(kNumParams);
  HandAnatomy anatomy;
  for (auto& f : anatomy.frames) f.setIdentity();
  const HandLimits limits = DefaultHandLimits();
  const std::vector<ceres::Jet<double, kNumParams>> xj = SeedJet<kNumParams>(x);
  std::vector<ceres::Jet<double, kNumParams>> angles(45), residuals(45);
  for (auto _ : state) {
    HandAnatomicalAngles(anatomy, xj.data() + 3, angles.data());
    LimitResiduals(limits, angles.data(), residuals.data());
    benchmark::DoNotOptimize(residuals.data());
  }
}

using Dual61 = Dual<kNumParams>;
using Jet61 = ceres::Jet<double, kNumParams>;

BENCHMARK(BM_PoseHandReference)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_AllVertices, double)
    ->Arg(4)
    ->Arg(16)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Keypoints, double)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Keypoints, Dual61)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Keypoints, Jet61)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KeypointsAnalyticJacobian)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AnatomyResidualsJet)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KeypointsPca12Jet)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_AllVertices, Dual61)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_AllVertices, Jet61)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace handlabel
