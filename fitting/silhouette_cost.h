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
// Together the two vanish only when the projected outline coincides with the mask's,
// so they neither shrink nor inflate the hand: at the true pose both are zero up to
// the pixel grid and the vertex spacing, and any scale change violates one of them.

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/camera_models.h"
#include "core/distance_transform.h"
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
};

// Bilinear lookup with clamping at the border; T may be a Jet (the weights carry the
// derivative).
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
          if (d > T(0.5)) r = (d - 0.5) * inv_sigma_;
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

}  // namespace handlabel
