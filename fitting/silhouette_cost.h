#pragma once
// Silhouette term: a symmetric 2D chamfer between the projected hand and the mask of
// every view, in one residual block (the forward pass runs once).
//
//   mesh -> mask   every listed vertex must project into the mask:
//                  r = max(0, D_mask(uv) - 0.5) / sigma_px, D_mask = distance to the
//                  nearest mask pixel centre (core/distance_transform.h), bilinearly
//                  interpolated; the 0.5 px allows for vertices on the true outline,
//                  which lies between the last inside and the first outside pixel
//                  centre. Alone this term would shrink the hand (a smaller hand lies
//                  inside the mask just as well).
//   mask -> mesh   every sampled outline point p of the mask (moved half a pixel
//                  outwards onto the pixel edge) must be reached by the projected hand:
//                  r = n . (uv_c - p) / sigma_px, with n the outline's outward normal
//                  and c the vertex whose projection is nearest to p (matched before
//                  each solve round, fixed during it, like ICP). Point-to-line, so
//                  vertices may slide along the outline. Alone this term would inflate
//                  the hand (a larger hand reaches every outline point).
// Views whose mask may be carved by occluders nobody masked (SilhouetteView::one_sided):
// observed hand pixels must be covered, the hand may reach beyond the mask. The outline
// half pulls only outwards, r = min(0, n . (uv_c - p)) / sigma_px, and the mesh -> mask
// half saturates, x = D - 0.5 becomes cap x / (cap + x) (cap_px; about x near the mask,
// never above cap): it still holds the hand's size against small excursions, while a
// finger far outside the mask (perhaps behind an object) is barely pulled (the slope
// falls as (cap / (cap + x))^2). Without the cap the outward-only outline inflates the
// hand.
// Two implementations: MultiViewSilhouetteCost (templated functor, autodiff) and
// MultiViewSilhouetteCostFunction (the vertices once in ceres::Jet, then every view's
// projection in doubles with its 2x3 Jacobian chained in: several times faster for 8
// views); tests check one against the other.
// Together the two vanish only when the projected outline coincides with the mask's,
// so they neither shrink nor inflate the hand: at the true pose both are zero up to
// the pixel grid and the vertex spacing, and any scale change violates one of them.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <vector>

#include "core/camera_models.h"
#include "core/distance_transform.h"
#include "core/dual.h"
#include "core/errors.h"
#include "core/hand_evaluator.h"
#include "core/rig.h"
#include "core/scalar_ops.h"

namespace handlabel {

struct SilhouetteView {
  RigCamera camera;
  DistanceImage distance_to_mask;               // height x width, pixels
  std::vector<Eigen::Vector2d> outline_px;      // mask outline samples (pixel edge)
  std::vector<Eigen::Vector2d> outline_normal;  // unit, pointing out of the mask
  std::vector<int> outline_vertex;  // per outline sample: index into vertex_ids
  bool one_sided = false;           // unknown occluders: see the header comment
  double cap_px = 3.0;              // mesh -> mask saturation of one-sided views (> 0)
};

// Bilinear lookup with clamping at the border; T may be a Jet (the weights carry the
// derivative).
// Every outline sample names an index into the cost's vertex_ids (or -1 for none):
// the residuals index the projected vertices with it, so it is checked at creation.
inline void CheckOutlineVertices(const std::vector<SilhouetteView>& views,
                                 size_t num_vertex_ids) {
  for (const SilhouetteView& view : views) {
    for (int c : view.outline_vertex) {
      HL_CHECK(c < static_cast<int>(num_vertex_ids), "outline vertex within vertex_ids");
    }
  }
}

template <typename T>
T BilinearLookup(const DistanceImage& image, const T& u, const T& v) {
  using std::floor;
  const int w = static_cast<int>(image.cols()), h = static_cast<int>(image.rows());
  const double u0 = std::floor(ScalarPart(u)), v0 = std::floor(ScalarPart(v));
  const T fu = u - u0, fv = v - v0;
  auto at = [&](double x, double y) {
    const int xi = std::min(std::max(static_cast<int>(x), 0), w - 1);
    const int yi = std::min(std::max(static_cast<int>(y), 0), h - 1);
    return image(yi, xi);
  };
  if (!(u0 > -1e6 && u0 < 1e6 && v0 > -1e6 && v0 < 1e6)) return T(at(0, 0));
  const double f00 = at(u0, v0), f10 = at(u0 + 1, v0), f01 = at(u0, v0 + 1),
               f11 = at(u0 + 1, v0 + 1);
  return (T(1.0) - fv) * ((T(1.0) - fu) * f00 + fu * f10) +
         fv * ((T(1.0) - fu) * f01 + fu * f11);
}

template <int kPoseDim = kNumPoseParams, int kNumBetas = 10>
class MultiViewSilhouetteCost {
 public:
  // `evaluator` and `views` must outlive the functor (the fitter re-matches outline
  // samples between rounds and rebuilds the functor).
  MultiViewSilhouetteCost(const HandEvaluator& evaluator,
                          const std::vector<int>& vertex_ids,
                          const std::vector<SilhouetteView>& views, double sigma_px)
      : evaluator_(evaluator),
        vertex_ids_(vertex_ids),
        views_(views),
        inv_sigma_(1.0 / sigma_px) {
    HL_CHECK(evaluator.pose_dim() == kPoseDim && evaluator.num_betas() == kNumBetas,
             "functor sizes differ from the evaluator's");
    for (const SilhouetteView& view : views_) {
      HL_CHECK(view.outline_px.size() == view.outline_normal.size() &&
                   view.outline_px.size() == view.outline_vertex.size(),
               "outline arrays differ in size");
    }
  }
  int num_residuals() const {
    int n = 0;
    for (const SilhouetteView& view : views_) {
      n += static_cast<int>(vertex_ids_.size() + view.outline_px.size());
    }
    return n;
  }

  template <typename T>
  bool operator()(const T* orient, const T* pose, const T* betas, const T* transl,
                  T* residuals) const {
    HandPoseState<T> state;
    evaluator_.Pose(orient, pose, betas, transl, &state);
    std::vector<T> vertices(3 * vertex_ids_.size());
    evaluator_.VerticesFromState(state, vertex_ids_, vertices.data());
    std::vector<T> uv(2 * vertex_ids_.size());
    std::vector<char> valid(vertex_ids_.size());
    int row = 0;
    for (const SilhouetteView& view : views_) {
      const Camera& cam = view.camera.camera;
      const Eigen::Matrix3d rot = view.camera.cam_from_world.rotation.toRotationMatrix();
      const Eigen::Vector3d& t = view.camera.cam_from_world.translation;
      T intrinsics[12];
      for (size_t i = 0; i < 12; ++i) {
        intrinsics[i] = T(i < cam.params().size() ? cam.params()[i] : 0.0);
      }
      for (size_t i = 0; i < vertex_ids_.size(); ++i) {
        const T* x = vertices.data() + 3 * i;
        T p[3];
        for (int r = 0; r < 3; ++r) {
          p[r] = T(t[r]) + rot(r, 0) * x[0] + rot(r, 1) * x[1] + rot(r, 2) * x[2];
        }
        valid[i] = ProjectToImage(cam.model(), intrinsics, p, &uv[2 * i]);
        T r = T(0.0);
        if (valid[i]) {
          const T d = BilinearLookup(view.distance_to_mask, uv[2 * i], uv[2 * i + 1]);
          if (d > T(0.5)) {
            const T x = d - 0.5;
            r = (view.one_sided ? view.cap_px * x / (view.cap_px + x) : x) * inv_sigma_;
          }
        }
        residuals[row++] = r;
      }
      for (size_t s = 0; s < view.outline_px.size(); ++s) {
        const int c = view.outline_vertex[s];
        T r = T(0.0);
        if (c >= 0 && valid[c]) {
          const Eigen::Vector2d& p = view.outline_px[s];
          const Eigen::Vector2d& n = view.outline_normal[s];
          r = (n[0] * (uv[2 * c] - p[0]) + n[1] * (uv[2 * c + 1] - p[1])) * inv_sigma_;
          if (view.one_sided && r > T(0.0)) r = T(0.0);
        }
        residuals[row++] = r;
      }
    }
    return true;
  }

  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<int>& vertex_ids,
                                     const std::vector<SilhouetteView>& views,
                                     double sigma_px) {
    CheckOutlineVertices(views, vertex_ids.size());
    auto* functor = new MultiViewSilhouetteCost(evaluator, vertex_ids, views, sigma_px);
    return new ceres::AutoDiffCostFunction<MultiViewSilhouetteCost, ceres::DYNAMIC, 3,
                                           kPoseDim, kNumBetas, 3>(
        functor, functor->num_residuals());
  }

 private:
  const HandEvaluator& evaluator_;
  std::vector<int> vertex_ids_;
  const std::vector<SilhouetteView>& views_;
  double inv_sigma_;
};

// Same residuals; the vertex subset is evaluated once with Jets over all parameters,
// projections are chained in doubles. Parameter blocks (3, kPoseDim, kNumBetas, 3).
template <int kPoseDim = kNumPoseParams, int kNumBetas = 10>
class MultiViewSilhouetteCostFunction : public ceres::CostFunction {
 public:
  static constexpr int kNumParams = 3 + kPoseDim + kNumBetas + 3;
  using Jet = ceres::Jet<double, kNumParams>;

  // `evaluator` and `views` must outlive the cost function.
  MultiViewSilhouetteCostFunction(const HandEvaluator& evaluator,
                                  const std::vector<int>& vertex_ids,
                                  const std::vector<SilhouetteView>& views,
                                  double sigma_px)
      : functor_(evaluator, vertex_ids, views, sigma_px),
        evaluator_(evaluator),
        vertex_ids_(vertex_ids),
        views_(views),
        inv_sigma_(1.0 / sigma_px) {
    set_num_residuals(functor_.num_residuals());
    mutable_parameter_block_sizes()->assign({3, kPoseDim, kNumBetas, 3});
  }
  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<int>& vertex_ids,
                                     const std::vector<SilhouetteView>& views,
                                     double sigma_px) {
    CheckOutlineVertices(views, vertex_ids.size());
    return new MultiViewSilhouetteCostFunction(evaluator, vertex_ids, views, sigma_px);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians == nullptr) {
      return functor_(parameters[0], parameters[1], parameters[2], parameters[3],
                      residuals);
    }
    const int sizes[4] = {3, kPoseDim, kNumBetas, 3};
    const int offsets[4] = {0, 3, 3 + kPoseDim, 3 + kPoseDim + kNumBetas};
    std::vector<Jet> blocks[4];
    for (int b = 0; b < 4; ++b) {
      blocks[b].resize(sizes[b]);
      for (int i = 0; i < sizes[b]; ++i)
        blocks[b][i] = Jet(parameters[b][i], offsets[b] + i);
    }
    auto state = std::make_unique<HandPoseState<Jet>>();
    evaluator_.Pose(blocks[0].data(), blocks[1].data(), blocks[2].data(),
                    blocks[3].data(), state.get());
    std::vector<Jet> vertices(3 * vertex_ids_.size());
    evaluator_.VerticesFromState(*state, vertex_ids_, vertices.data());

    const int n = num_residuals();
    Eigen::Matrix<double, Eigen::Dynamic, kNumParams, Eigen::RowMajor> jac(n, kNumParams);
    jac.setZero();
    std::vector<Eigen::Vector2d> uv(vertex_ids_.size());
    std::vector<Eigen::Matrix<double, 2, kNumParams>> uv_jac(vertex_ids_.size());
    std::vector<char> valid(vertex_ids_.size());
    int row = 0;
    for (const SilhouetteView& view : views_) {
      const Eigen::Matrix3d rot = view.camera.cam_from_world.rotation.toRotationMatrix();
      const Eigen::Vector3d& t = view.camera.cam_from_world.translation;
      for (size_t i = 0; i < vertex_ids_.size(); ++i) {
        const Jet* x = vertices.data() + 3 * i;
        const Eigen::Vector3d p = rot * Eigen::Vector3d(x[0].a, x[1].a, x[2].a) + t;
        Eigen::Matrix<double, 2, 3> d_point;
        valid[i] = view.camera.camera.ProjectWithJacobian(p, &uv[i], &d_point);
        double r = 0.0;
        if (valid[i]) {
          Eigen::Matrix<double, 3, kNumParams> dx;
          dx.row(0) = x[0].v.transpose();
          dx.row(1) = x[1].v.transpose();
          dx.row(2) = x[2].v.transpose();
          uv_jac[i].noalias() = d_point * rot * dx;
          double f, dfdu, dfdv;
          BilinearWithGradient(view.distance_to_mask, uv[i], &f, &dfdu, &dfdv);
          if (f > 0.5) {
            const double x = f - 0.5, cap = view.cap_px;
            // d r / d x: 1, or (cap / (cap + x))^2 when saturated.
            const double slope = view.one_sided ? std::pow(cap / (cap + x), 2) : 1.0;
            r = (view.one_sided ? cap * x / (cap + x) : x) * inv_sigma_;
            jac.row(row) =
                inv_sigma_ * slope * (dfdu * uv_jac[i].row(0) + dfdv * uv_jac[i].row(1));
          }
        }
        residuals[row++] = r;
      }
      for (size_t s = 0; s < view.outline_px.size(); ++s) {
        const int c = view.outline_vertex[s];
        double r = 0.0;
        if (c >= 0 && valid[c]) {
          const Eigen::Vector2d& nrm = view.outline_normal[s];
          r = nrm.dot(uv[c] - view.outline_px[s]) * inv_sigma_;
          if (view.one_sided && r > 0.0) {
            r = 0.0;
          } else {
            jac.row(row) =
                inv_sigma_ * (nrm[0] * uv_jac[c].row(0) + nrm[1] * uv_jac[c].row(1));
          }
        }
        residuals[row++] = r;
      }
    }
    for (int b = 0; b < 4; ++b) {
      if (jacobians[b] == nullptr) continue;
      for (int r = 0; r < n; ++r) {
        for (int c = 0; c < sizes[b]; ++c) {
          jacobians[b][r * sizes[b] + c] = jac(r, offsets[b] + c);
        }
      }
    }
    return true;
  }

 private:
  // BilinearLookup's value and gradient in doubles (same cell and clamping).
  static void BilinearWithGradient(const DistanceImage& image, const Eigen::Vector2d& uv,
                                   double* f, double* dfdu, double* dfdv) {
    using D = Dual<2>;
    const D value = BilinearLookup(image, D(uv.x(), 0), D(uv.y(), 1));
    *f = value.a;
    *dfdu = value.v[0];
    *dfdv = value.v[1];
  }

  MultiViewSilhouetteCost<kPoseDim, kNumBetas> functor_;
  const HandEvaluator& evaluator_;
  std::vector<int> vertex_ids_;
  const std::vector<SilhouetteView>& views_;
  double inv_sigma_;
};

}  // namespace handlabel
