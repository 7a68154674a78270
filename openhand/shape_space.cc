#include "openhand/shape_space.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/errors.h"

namespace handlabel {
namespace {

// x -> offset + linear * x.
struct AffineMap {
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    return offset + linear * x;
  }
};

// Bone j moves from (joint a, child b, radius r) to (a2, b2, r2).
AffineMap BoneMap(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r,
                  const Eigen::Vector3d& a2, const Eigen::Vector3d& b2, double r2) {
  const Eigen::Vector3d d = (b - a).normalized();
  const double along = (b2 - a2).norm() / (b - a).norm();
  const double across = r2 / r;
  const Eigen::Matrix3d stretch =
      along * d * d.transpose() +
      across * (Eigen::Matrix3d::Identity() - d * d.transpose());
  const Eigen::Matrix3d turn =
      Eigen::Quaterniond::FromTwoVectors(d, (b2 - a2).normalized()).toRotationMatrix();
  AffineMap m;
  m.linear = turn * stretch;
  m.offset = a2 - m.linear * a;
  return m;
}

// Palm: affine in the palm plane (x, z) through the wrist, fitted to the MCP and CMC
// joints; y scales with the palm thickness about the wrist.
AffineMap PalmMap(const OpenHandSkeleton& from, const OpenHandSkeleton& to,
                  double thickness_ratio) {
  const int ids[] = {1, 4, 7, 10, 13};
  Eigen::Matrix<double, 5, 2> p, q;
  for (int k = 0; k < 5; ++k) {
    const Eigen::Vector3d d = from.joints[ids[k]] - from.joints[0];
    const Eigen::Vector3d e = to.joints[ids[k]] - to.joints[0];
    p.row(k) << d.x(), d.z();
    q.row(k) << e.x(), e.z();
  }
  const Eigen::Matrix2d m =
      (p.transpose() * p).ldlt().solve(p.transpose() * q).transpose();
  AffineMap map;
  map.linear.setZero();
  map.linear(0, 0) = m(0, 0);
  map.linear(0, 2) = m(0, 1);
  map.linear(2, 0) = m(1, 0);
  map.linear(2, 2) = m(1, 1);
  map.linear(1, 1) = thickness_ratio;
  map.offset = to.joints[0] - map.linear * from.joints[0];
  return map;
}

}  // namespace

std::vector<Eigen::Vector3d> DeformToDesign(const std::vector<Eigen::Vector3d>& vertices,
                                            const SkinningWeights& weights,
                                            const OpenHandDesign& from,
                                            const OpenHandDesign& target) {
  const OpenHandSkeleton a = SkeletonFromDesign(from);
  const OpenHandSkeleton b = SkeletonFromDesign(target);
  std::array<AffineMap, kNumHandJoints> maps;
  maps[0] = PalmMap(a, b, target.palm_thickness / from.palm_thickness);
  const auto chains = OpenHandChains();
  for (int c = 0; c < 5; ++c) {
    for (int k = 0; k < 3; ++k) {
      const int j = chains[c][k];
      const Eigen::Vector3d& ca = k < 2 ? a.joints[chains[c][k + 1]] : a.tips[c];
      const Eigen::Vector3d& cb = k < 2 ? b.joints[chains[c][k + 1]] : b.tips[c];
      maps[j] = BoneMap(a.joints[j], ca, a.radii[j], b.joints[j], cb, b.radii[j]);
    }
  }
  std::vector<Eigen::Vector3d> out(vertices.size(), Eigen::Vector3d::Zero());
  for (size_t v = 0; v < vertices.size(); ++v) {
    for (int j = 0; j < kNumHandJoints; ++j) {
      const double wj = weights(static_cast<Eigen::Index>(v), j);
      if (wj != 0.0) out[v] += wj * maps[j](vertices[v]);
    }
  }
  return out;
}

OpenHandShapeSpace BuildOpenHandShapeSpace(const std::vector<Eigen::Vector3d>& vertices,
                                           const SkinningWeights& weights,
                                           const OpenHandDesign& design,
                                           const OpenHandVariation& variation,
                                           int num_components, int num_samples,
                                           std::mt19937_64& rng) {
  HL_CHECK(num_components >= 1 && num_samples >= num_components,
           "need at least as many shape samples as components");
  const int nv = static_cast<int>(vertices.size());
  const int dim = 3 * nv + 3 * kNumHandJoints;
  const OpenHandSkeleton base = SkeletonFromDesign(design);
  Eigen::MatrixXd offsets(num_samples, dim);
  for (int s = 0; s < num_samples; ++s) {
    const OpenHandDesign sample = SampleOpenHandDesign(design, variation, rng);
    const std::vector<Eigen::Vector3d> deformed =
        DeformToDesign(vertices, weights, design, sample);
    const OpenHandSkeleton sk = SkeletonFromDesign(sample);
    for (int v = 0; v < nv; ++v)
      offsets.row(s).segment<3>(3 * v) = deformed[v] - vertices[v];
    for (int j = 0; j < kNumHandJoints; ++j) {
      offsets.row(s).segment<3>(3 * nv + 3 * j) = sk.joints[j] - base.joints[j];
    }
  }
  // PCA about the default through the small Gram matrix (samples x samples).
  const Eigen::MatrixXd gram = offsets * offsets.transpose() / num_samples;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  HL_CHECK(eig.info() == Eigen::Success, "shape PCA failed");
  const double total = gram.trace();
  OpenHandShapeSpace space;
  space.vertex_dirs.resize(3 * nv, num_components);
  space.joint_dirs.resize(3 * kNumHandJoints, num_components);
  space.stddev.resize(num_components);
  double kept = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& v : vertices) centroid += v / nv;
  for (int k = 0; k < num_components; ++k) {
    const int col = num_samples - 1 - k;  // eigenvalues ascend
    const double lambda = std::max(eig.eigenvalues()[col], 0.0);
    kept += lambda;
    // Unit direction in offset space; scaled by the standard deviation below.
    Eigen::VectorXd dir = offsets.transpose() * eig.eigenvectors().col(col);
    dir /= dir.norm();
    // Sign: +beta moves vertices away from the centroid on average (grows the hand).
    double grow = 0.0;
    for (int v = 0; v < nv; ++v)
      grow += dir.segment<3>(3 * v).dot(vertices[v] - centroid);
    if (grow < 0) dir = -dir;
    const double sd = std::sqrt(lambda);
    space.stddev[k] = sd;
    space.vertex_dirs.col(k) = sd * dir.head(3 * nv);
    space.joint_dirs.col(k) = sd * dir.tail(3 * kNumHandJoints);
  }
  space.explained = total > 0 ? kept / total : 1.0;
  return space;
}

}  // namespace handlabel
