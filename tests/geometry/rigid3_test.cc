#include "geometry/rigid3.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MatrixNear;
using testing::RandomRotation;
using testing::RandomVector3;
using testing::Rigid3Near;

TEST(Rigid3, ComposeAndInverseAgreeWithMatrices) {
  for (int i = 0; i < 100; ++i) {
    const Rigid3 a_from_b(RandomRotation(), RandomVector3(-2, 2));
    const Rigid3 b_from_c(RandomRotation(), RandomVector3(-2, 2));
    const Eigen::Vector3d p = RandomVector3(-1, 1);
    Eigen::Matrix4d ma = Eigen::Matrix4d::Identity(), mb = Eigen::Matrix4d::Identity();
    ma.topRows<3>() = a_from_b.ToMatrix();
    mb.topRows<3>() = b_from_c.ToMatrix();
    const Eigen::Vector4d expected = ma * mb * p.homogeneous();
    EXPECT_THAT((a_from_b * b_from_c) * p, MatrixNear(expected.head<3>(), 1e-12));
    EXPECT_THAT(a_from_b.Inverse() * (a_from_b * p), MatrixNear(p, 1e-12));
    EXPECT_THAT(a_from_b * a_from_b.Inverse(), Rigid3Near(Rigid3(), 1e-12, 1e-12));
  }
}

// Bit for bit what applying the transform to each point gives: the labels' ground truth
// went through that arithmetic before TransformPoints existed.
TEST(Rigid3, TransformPointsAppliesTheTransformToEveryRow) {
  const Rigid3 b_from_a(RandomRotation(), RandomVector3(-2, 2));
  Points3d points(21, 3);
  for (int i = 0; i < points.rows(); ++i)
    points.row(i) = RandomVector3(-1, 1).transpose();
  const Points3d moved = TransformPoints(b_from_a, points);
  ASSERT_EQ(moved.rows(), points.rows());
  for (int i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d expected =
        b_from_a * Eigen::Vector3d(points.row(i).transpose());
    for (int c = 0; c < 3; ++c) EXPECT_EQ(moved(i, c), expected[c]) << i;
  }
  EXPECT_EQ(TransformPoints(b_from_a, Points3d(0, 3)).rows(), 0);
}

TEST(Rigid3, FromMatrixRoundTripsAndRepairsSlightlyNonOrthogonalInput) {
  const Rigid3 t(RandomRotation(), RandomVector3(-1, 1));
  EXPECT_THAT(Rigid3::FromMatrix(t.ToMatrix()), Rigid3Near(t, 1e-12, 1e-12));
  Matrix3x4d noisy = t.ToMatrix();
  noisy(0, 1) += 1e-6;  // as written by a text file with 6 decimals
  EXPECT_THAT(Rigid3::FromMatrix(noisy), Rigid3Near(t, 1e-5, 1e-12));
}

TEST(Rigid3, StorageIsXyzwThenTranslationAsDocumented) {
  const Eigen::Quaterniond q(0.5, 0.5, -0.5, 0.5);  // (w, x, y, z)
  Rigid3 t(q, Eigen::Vector3d(1, 2, 3));
  const double* coeffs = t.rotation.coeffs().data();
  EXPECT_EQ(coeffs[0], 0.5);   // x
  EXPECT_EQ(coeffs[2], 0.5);   // z
  EXPECT_EQ(coeffs[1], -0.5);  // y
  EXPECT_EQ(coeffs[3], 0.5);   // w
  EXPECT_EQ(t.translation.data()[2], 3.0);
}

TEST(Rigid3, SourceOriginIsCameraCentre) {
  const Rigid3 cam_from_world(RandomRotation(), RandomVector3(-1, 1));
  const Eigen::Vector3d centre = cam_from_world.SourceOrigin();
  EXPECT_THAT(cam_from_world * centre, MatrixNear(Eigen::Vector3d::Zero(), 1e-12));
}

}  // namespace
}  // namespace handlabel
