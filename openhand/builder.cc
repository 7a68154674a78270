#include "openhand/builder.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/errors.h"
#include "core/option_checks.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_pose_sampler.h"
#include "openhand/implicit_mesher.h"
#include "openhand/mesh_checks.h"
#include "openhand/nnls.h"
#include "openhand/shape_space.h"

namespace handlabel {
namespace {

// Moves p onto the zero set of the shape along the gradient (a few Newton steps).
Eigen::Vector3d ProjectToSurface(const OpenHandShape& shape, Eigen::Vector3d p) {
  for (int it = 0; it < 4; ++it) {
    const double f = shape.Evaluate(p);
    const Eigen::Vector3d g = shape.Gradient(p);
    const double g2 = g.squaredNorm();
    if (g2 < 1e-12) break;
    Eigen::Vector3d step = f * g / g2;
    if (step.norm() > 0.002) step *= 0.002 / step.norm();  // stay local
    p -= step;
    if (std::abs(f) < 1e-7) break;
  }
  return p;
}

Points3d ToPoints(const std::vector<Eigen::Vector3d>& v) {
  Points3d p(static_cast<Eigen::Index>(v.size()), 3);
  for (size_t i = 0; i < v.size(); ++i) p.row(i) = v[i].transpose();
  return p;
}

// Tangential relaxation onto the surface, one round at a time; moves that make faces
// cross (relaxing across the creases between neighbouring fingers can) are undone.
void RelaxWithoutIntersections(TriangleMesh* mesh, int iterations,
                               const OpenHandShape& shape) {
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces(mesh->faces.size(), 3);
  for (size_t f = 0; f < mesh->faces.size(); ++f)
    faces.row(f) = mesh->faces[f].transpose();
  for (int it = 0; it < iterations; ++it) {
    const std::vector<Eigen::Vector3d> before = mesh->vertices;
    RelaxMesh(mesh, 1,
              [&](const Eigen::Vector3d& p) { return ProjectToSurface(shape, p); });
    for (int round = 0; round < 50; ++round) {
      const auto pairs = SelfIntersectingFacePairs(ToPoints(mesh->vertices), faces);
      if (pairs.empty()) break;
      for (const auto& [f, g] : pairs) {
        for (int k = 0; k < 3; ++k) {
          mesh->vertices[faces(f, k)] = before[faces(f, k)];
          mesh->vertices[faces(g, k)] = before[faces(g, k)];
        }
      }
    }
  }
}

// Direction of the bone leaving joint j (wrist: towards the middle knuckle).
Eigen::Vector3d BoneAxis(const OpenHandSkeleton& sk, int j) {
  if (j == 0) return (sk.joints[4] - sk.joints[0]).normalized();
  const auto chains = OpenHandChains();
  for (int c = 0; c < 5; ++c) {
    for (int k = 0; k < 3; ++k) {
      if (chains[c][k] != j) continue;
      const Eigen::Vector3d& child = k < 2 ? sk.joints[chains[c][k + 1]] : sk.tips[c];
      return (child - sk.joints[j]).normalized();
    }
  }
  return Eigen::Vector3d::UnitX();
}

// Joint regressor row of joint j: weights >= 0 summing to 1 over the vertices near the
// joint, fitted to the joint of the mean shape and of every shape direction.
Eigen::SparseVector<double> FitRegressorRow(const std::vector<Eigen::Vector3d>& vertices,
                                            const Eigen::MatrixXd& vertex_dirs,
                                            const Eigen::MatrixXd& joint_dirs, int j,
                                            const Eigen::Vector3d& joint,
                                            const Eigen::Vector3d& axis, double radius,
                                            double* max_error, double* max_error_mean) {
  // Support: the ring of vertices around the joint, across the bone axis (a distance
  // that counts axial offsets 3x), so the joint lies inside their convex hull even
  // deep in the palm.
  std::vector<std::pair<double, int>> near;
  for (int v = 0; v < static_cast<int>(vertices.size()); ++v) {
    const Eigen::Vector3d q = vertices[v] - joint;
    const double axial = q.dot(axis);
    const double radial2 = q.squaredNorm() - axial * axial;
    const double d = std::sqrt(std::max(radial2, 0.0) + 9.0 * axial * axial);
    if (d < radius) near.emplace_back(d, v);
  }
  std::sort(near.begin(), near.end());
  if (near.size() > 64) near.resize(64);
  HL_CHECK(near.size() >= 4, "too few vertices around joint " + std::to_string(j));
  const int n = static_cast<int>(near.size());
  const int k = static_cast<int>(vertex_dirs.cols());
  // Rows (millimetres, relative to the joint, so every target is 0): 3 for the mean
  // shape, 3 per shape direction, 1 sum-to-one row and n small ridge rows that prefer
  // spreading the weight. The solution is rescaled to sum to 1 exactly afterwards,
  // which keeps the homogeneous rows at 0.
  const double kMm = 1000.0, kRidge = 1e-3;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3 + 3 * k + 1 + n, n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(a.rows());
  for (int i = 0; i < n; ++i) {
    const int v = near[i].second;
    a.block<3, 1>(0, i) = kMm * (vertices[v] - joint);
    for (int c = 0; c < k; ++c) {
      a.block<3, 1>(3 + 3 * c, i) =
          kMm * (vertex_dirs.block<3, 1>(3 * v, c) - joint_dirs.block<3, 1>(3 * j, c));
    }
    a(3 + 3 * k, i) = 1.0;
    a(4 + 3 * k + i, i) = kRidge;
  }
  b[3 + 3 * k] = 1.0;
  for (int i = 0; i < n; ++i) b[4 + 3 * k + i] = kRidge / n;
  Eigen::VectorXd x = SolveNnls(a, b);
  HL_CHECK(x.sum() > 0, "joint regressor fit failed for joint " + std::to_string(j));
  x /= x.sum();
  const Eigen::VectorXd r = a.topRows(3 + 3 * k) * x / kMm;
  *max_error_mean = std::max(*max_error_mean, r.head<3>().norm());
  for (int c = 0; c <= k; ++c)
    *max_error = std::max(*max_error, r.segment<3>(3 * c).norm());
  Eigen::SparseVector<double> row(static_cast<Eigen::Index>(vertices.size()));
  std::vector<std::pair<int, double>> entries;
  for (int i = 0; i < n; ++i)
    if (x[i] > 0) entries.emplace_back(near[i].second, x[i]);
  std::sort(entries.begin(), entries.end());
  for (const auto& [v, w] : entries) row.insert(v) = w;
  return row;
}

}  // namespace

void OpenHandBuildOptions::Check(const std::string& source) const {
  RequireInRange(source, "grid_step", grid_step, 2e-4, 5e-3,
                 "a spacing in [0.0002, 0.005] m");
  RequireInRange(source, "target_vertices", target_vertices, 200, 20000, "200 to 20000");
  RequireInRange(source, "relax_iterations", relax_iterations, 0, 100, "0 to 100");
  RequireInRange(source, "num_betas", num_betas, 1, 20, "1 to 20");
  if (num_shape_samples < num_betas || num_shape_samples > 5000) {
    throw InputError(source, "num_shape_samples", "num_betas to 5000",
                     std::to_string(num_shape_samples));
  }
  RequireInRange(source, "num_pose_samples", num_pose_samples, 100, 100000,
                 "100 to 100000");
  RequireInRange(source, "regressor_radius", regressor_radius, 0.5, 5, "0.5 to 5");
  // The parts keep their own names in messages, as their fields are theirs.
  variation.Check("open hand variation");
  skinning.Check("skinning options");
}

namespace {

// Step 1: the design's implicit surface meshed finely, decimated to the target size
// and relaxed without self-intersections.
TriangleMesh BuildSurface(const OpenHandShape& shape, const OpenHandBuildOptions& options,
                          OpenHandBuildReport* report) {
  Eigen::Vector3d lo, hi;
  shape.Bounds(&lo, &hi);
  ImplicitMesherOptions mesher;
  mesher.step = options.grid_step;
  const TriangleMesh fine = MeshImplicitSurface(
      [&](const Eigen::Vector3d& p) { return shape.Evaluate(p); }, lo, hi, mesher);
  report->fine_vertices = static_cast<int>(fine.vertices.size());
  report->fine_faces = static_cast<int>(fine.faces.size());
  DecimationOptions decimation;
  decimation.target_vertices = options.target_vertices;
  decimation.improve_by_flips = true;
  TriangleMesh mesh = DecimateMesh(fine, decimation);
  RelaxWithoutIntersections(&mesh, options.relax_iterations, shape);
  return mesh;
}

// Step 4: each joint's regressor row, fitted over the vertices near it.
Eigen::SparseMatrix<double, Eigen::RowMajor> BuildJointRegressor(
    const TriangleMesh& mesh, const OpenHandShapeSpace& space,
    const OpenHandSkeleton& skeleton, const OpenHandBuildOptions& options,
    OpenHandBuildReport* report) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int j = 0; j < kNumHandJoints; ++j) {
    const double radius = options.regressor_radius * skeleton.radii[j];
    const Eigen::SparseVector<double> row =
        FitRegressorRow(mesh.vertices, space.vertex_dirs, space.joint_dirs, j,
                        skeleton.joints[j], BoneAxis(skeleton, j), radius,
                        &report->max_regressor_error, &report->max_regressor_error_mean);
    for (Eigen::SparseVector<double>::InnerIterator it(row); it; ++it)
      triplets.emplace_back(j, static_cast<int>(it.index()), it.value());
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> regressor;
  regressor.resize(kNumHandJoints, static_cast<int>(mesh.vertices.size()));
  regressor.setFromTriplets(triplets.begin(), triplets.end());
  return regressor;
}

// Step 5: the vertex nearest to each designed fingertip.
std::array<int, 5> NearestTipVertices(const TriangleMesh& mesh,
                                      const OpenHandSkeleton& skeleton) {
  std::array<int, 5> tips{};
  const int nv = static_cast<int>(mesh.vertices.size());
  for (int t = 0; t < 5; ++t) {
    int best = 0;
    for (int v = 1; v < nv; ++v) {
      if ((mesh.vertices[v] - skeleton.tips[t]).squaredNorm() <
          (mesh.vertices[best] - skeleton.tips[t]).squaredNorm())
        best = v;
    }
    tips[t] = best;
  }
  return tips;
}

// Step 6: pose PCA from natural poses (open, fist, pinch, point, random within
// limits) sampled on the model's anatomy; sets pose_mean and pose_pca_basis.
void BuildPosePca(const OpenHandBuildOptions& options, std::mt19937_64& rng,
                  HandModel* model, OpenHandBuildReport* report) {
  const HandAnatomy anatomy = ComputeHandAnatomy(*model);
  const HandLimits limits = DefaultHandLimits();
  HandPoseSamplerOptions sampler;
  Eigen::MatrixXd poses(options.num_pose_samples, kNumPoseParams);
  for (int s = 0; s < options.num_pose_samples; ++s) {
    poses.row(s) = SampleHandPose(anatomy, limits, sampler, rng).hand_pose.transpose();
  }
  model->pose_mean = poses.colwise().mean().transpose();
  const Eigen::MatrixXd centred = poses.rowwise() - model->pose_mean.transpose();
  const Eigen::MatrixXd cov = centred.transpose() * centred / options.num_pose_samples;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  HL_CHECK(eig.info() == Eigen::Success, "pose PCA failed");
  model->pose_pca_basis.resize(kNumPoseParams, kNumPoseParams);
  double first6 = 0.0;
  for (int k = 0; k < kNumPoseParams; ++k) {
    Eigen::VectorXd dir = eig.eigenvectors().col(kNumPoseParams - 1 - k);
    Eigen::Index big;
    dir.cwiseAbs().maxCoeff(&big);
    if (dir[big] < 0) dir = -dir;  // deterministic sign: largest entry positive
    model->pose_pca_basis.row(k) = dir.transpose();
    if (k < 6) first6 += eig.eigenvalues()[kNumPoseParams - 1 - k];
  }
  report->pose_variance_explained_6 = first6 / cov.trace();
}

}  // namespace

HandModel BuildOpenHand(const OpenHandDesign& design, const OpenHandBuildOptions& options,
                        OpenHandBuildReport* report) {
  options.Check("open hand build options");
  OpenHandBuildReport local_report;
  if (!report) report = &local_report;
  const OpenHandShape shape = ShapeFromDesign(design);
  const OpenHandSkeleton skeleton = SkeletonFromDesign(design);

  const TriangleMesh mesh = BuildSurface(shape, options, report);
  const int nv = static_cast<int>(mesh.vertices.size());
  HandModel model;
  model.name = "open_hand_right";
  model.side = HandSide::kRight;
  model.v_template.resize(nv, 3);
  for (int v = 0; v < nv; ++v) model.v_template.row(v) = mesh.vertices[v].transpose();
  model.faces.resize(static_cast<Eigen::Index>(mesh.faces.size()), 3);
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    model.faces.row(f) = mesh.faces[f].transpose();

  // 2. Skinning.
  model.skinning_weights = OpenHandSkinningWeights(mesh, skeleton, options.skinning);
  // 3. Shapes (plain LBS: no pose blend shapes).
  std::mt19937_64 rng(options.seed);
  const OpenHandShapeSpace space = BuildOpenHandShapeSpace(
      mesh.vertices, model.skinning_weights, design, options.variation, options.num_betas,
      options.num_shape_samples, rng);
  model.shapedirs = space.vertex_dirs;
  report->shape_variance_explained = space.explained;
  model.posedirs = Eigen::MatrixXd::Zero(3 * nv, 9 * (kNumHandJoints - 1));
  // 4-6.
  model.joint_regressor = BuildJointRegressor(mesh, space, skeleton, options, report);
  model.tip_vertex_ids = NearestTipVertices(mesh, skeleton);
  BuildPosePca(options, rng, &model, report);

  model.Check("open hand builder");
  return options.side == HandSide::kLeft ? MirrorHandModel(model) : model;
}

HandModel MirrorHandModel(const HandModel& in) {
  HandModel out = in;
  out.side = in.side == HandSide::kRight ? HandSide::kLeft : HandSide::kRight;
  const std::string from = HandSideName(in.side), to = HandSideName(out.side);
  const size_t at = out.name.rfind(from);
  if (at != std::string::npos) out.name.replace(at, from.size(), to);
  out.v_template.col(0) *= -1.0;
  out.faces.col(1).swap(out.faces.col(2));
  for (Eigen::Index r = 0; r < out.shapedirs.rows(); r += 3) out.shapedirs.row(r) *= -1.0;
  // A mirrored rotation M R M (M = diag(-1, 1, 1)): (R - I)(r, s) changes sign when
  // exactly one of r, s is 0, and the x rows of the offsets change sign.
  for (Eigen::Index c = 0; c < out.posedirs.cols(); ++c) {
    const int rs = static_cast<int>(c % 9);
    const bool flip_feature = (rs / 3 == 0) != (rs % 3 == 0);
    for (Eigen::Index r = 0; r < out.posedirs.rows(); ++r) {
      const bool flip_row = r % 3 == 0;
      if (flip_feature != flip_row) out.posedirs(r, c) *= -1.0;
    }
  }
  // Axis-angle of M R M is (x, -y, -z).
  for (int k = 0; k < kNumPoseParams; ++k) {
    if (k % 3 == 0) continue;
    if (out.pose_mean.size()) out.pose_mean[k] *= -1.0;
    if (out.pose_pca_basis.size()) out.pose_pca_basis.col(k) *= -1.0;
  }
  return out;
}

}  // namespace handlabel
