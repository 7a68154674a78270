#pragma once
// Silhouette term: a symmetric 2D chamfer between the projected hand and the mask of
// every view, in one residual block (the forward pass runs once).
//
//   mesh -> mask   every listed vertex must project into the mask:
//                  r = max(0, D_mask(uv) - 0.5) / sigma_px, D_mask = distance to the
//                  nearest mask pixel centre (image/distance_transform.h), bilinearly
//                  interpolated; the 0.5 px allows for vertices on the true outline,
//                  which lies between the last inside and the first outside pixel
//                  centre (SilhouetteView::inside_px: more for eroded masks, see
//                  HandFitOptions::mask_margin_max_px). Alone this term would shrink the
//                  hand (a smaller hand lies inside the mask just as well).
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
// Distances come from a window of the image around the hand (SilhouetteView::
// distance_to_mask, origin distance_origin); beyond the window the distance grows with
// the distance to it (the window's border value plus the distance to the border: an
// upper bound, continuous, pointing back). Beyond the image it stays the border's, as
// with a whole-image transform: the hand may continue outside the picture.
// Two implementations: MultiViewSilhouetteCost (templated functor, autodiff, one
// residual per vertex and outline sample: the reference) and
// MultiViewSilhouetteSquareRootCost (what the fitter uses: projections in doubles,
// analytic vertex Jacobians (HandEvaluator::VerticesAndJacobian) of only the vertices
// with a non-zero row, the term in square-root form, fitting/
// point_term_normal_equations.h); tests check that both give the same cost, gradient
// and Gauss-Newton matrix.
// Together the two vanish only when the projected outline coincides with the mask's,
// so they neither shrink nor inflate the hand: at the true pose both are zero up to
// the pixel grid and the vertex spacing, and any scale change violates one of them.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/errors.h"
#include "fitting/point_term_normal_equations.h"
#include "geometry/camera_models.h"
#include "geometry/rig.h"
#include "geometry/scalar_ops.h"
#include "hand/hand_evaluator.h"
#include "image/distance_transform.h"

namespace handlabel {

struct SilhouetteView {
  RigCamera camera;
  // Distance to the mask (pixels) over a window of the image whose entry (0, 0) is
  // pixel distance_origin (x, y); the whole image when the origin is (0, 0) and the
  // size the camera's.
  DistanceImage distance_to_mask;
  Eigen::Vector2i distance_origin = Eigen::Vector2i::Zero();
  std::vector<Eigen::Vector2d> outline_px;      // mask outline samples (pixel edge)
  std::vector<Eigen::Vector2d> outline_normal;  // unit, pointing out of the mask
  std::vector<int> outline_vertex;  // per outline sample: index into vertex_ids
  bool one_sided = false;           // unknown occluders: see the header comment
  double cap_px = 3.0;              // mesh -> mask saturation of one-sided views (> 0)
  double inside_px = 0.5;           // mesh -> mask distance that costs nothing
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

// A pixel coordinate clamped to the image (0 .. size - 1): beyond the image the hand is
// not observed, so the distance stays the border's (no pull back into the image).
template <typename T>
T ClampToImage(const T& u, int size) {
  if (u < T(0.0)) return T(0.0);
  if (u > T(size - 1.0)) return T(size - 1.0);
  return u;
}

// The distance of pixel position (u, v) (image coordinates) to the mask: bilinear in the
// window, plus the distance to the window beyond it (header comment).
template <typename T>
T DistanceLookup(const SilhouetteView& view, const T& u, const T& v) {
  using std::sqrt;
  const double max_x = static_cast<double>(view.distance_to_mask.cols() - 1);
  const double max_y = static_cast<double>(view.distance_to_mask.rows() - 1);
  const T x = ClampToImage(u, view.camera.camera.width()) -
              static_cast<double>(view.distance_origin.x());
  const T y = ClampToImage(v, view.camera.camera.height()) -
              static_cast<double>(view.distance_origin.y());
  const T xc = x < T(0.0) ? T(0.0) : (x > T(max_x) ? T(max_x) : x);
  const T yc = y < T(0.0) ? T(0.0) : (y > T(max_y) ? T(max_y) : y);
  const T inside = BilinearLookup(view.distance_to_mask, xc, yc);
  const T dx = x - xc, dy = y - yc;
  if (dx == T(0.0) && dy == T(0.0)) return inside;
  return inside + sqrt(dx * dx + dy * dy);
}

// DistanceLookup's value and gradient in doubles (the same cell and extension).
inline double DistanceWithGradient(const SilhouetteView& view, const Eigen::Vector2d& uv,
                                   Eigen::Vector2d* gradient) {
  const DistanceImage& image = view.distance_to_mask;
  const int w = static_cast<int>(image.cols()), h = static_cast<int>(image.rows());
  if (!(std::abs(uv.x()) < 1e6 && std::abs(uv.y()) < 1e6)) {  // far off or NaN: flat
    gradient->setZero();
    return image(0, 0);
  }
  const double u = ClampToImage(uv.x(), view.camera.camera.width());
  const double v = ClampToImage(uv.y(), view.camera.camera.height());
  const double x = u - view.distance_origin.x();
  const double y = v - view.distance_origin.y();
  const double xc = std::clamp(x, 0.0, w - 1.0), yc = std::clamp(y, 0.0, h - 1.0);
  const int x0 = std::min(static_cast<int>(xc), std::max(w - 2, 0));
  const int y0 = std::min(static_cast<int>(yc), std::max(h - 2, 0));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = xc - x0, fy = yc - y0;
  const double f00 = image(y0, x0), f10 = image(y0, x1), f01 = image(y1, x0),
               f11 = image(y1, x1);
  double value =
      (1 - fy) * ((1 - fx) * f00 + fx * f10) + fy * ((1 - fx) * f01 + fx * f11);
  // Inside the window; on a clamped axis the window's value does not change.
  *gradient = Eigen::Vector2d(x == xc ? (1 - fy) * (f10 - f00) + fy * (f11 - f01) : 0.0,
                              y == yc ? (1 - fx) * (f01 - f00) + fx * (f11 - f10) : 0.0);
  const Eigen::Vector2d outside(x - xc, y - yc);
  const double beyond = outside.norm();
  if (beyond > 0.0) {
    value += beyond;
    *gradient += outside / beyond;
  }
  // No derivative along an axis clamped to the image.
  if (u != uv.x()) (*gradient)[0] = 0.0;
  if (v != uv.y()) (*gradient)[1] = 0.0;
  return value;
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
          const T d = DistanceLookup(view, uv[2 * i], uv[2 * i + 1]);
          if (d > T(view.inside_px)) {
            const T x = d - view.inside_px;
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

// The same term in square-root form (fitting/point_term_normal_equations.h): num_params
// + 1 residuals with the same cost, gradient and Gauss-Newton matrix as
// MultiViewSilhouetteCost. Projections and distance gradients in doubles; vertex
// Jacobians (analytic) only for the vertices with a non-zero row (outside the mask or
// matched by an outline sample). Parameter blocks (3, pose_dim, num_betas, 3).
class MultiViewSilhouetteSquareRootCost : public ceres::CostFunction {
 public:
  // `evaluator` and `views` must outlive the cost function.
  MultiViewSilhouetteSquareRootCost(const HandEvaluator& evaluator,
                                    const std::vector<int>& vertex_ids,
                                    const std::vector<SilhouetteView>& views,
                                    double sigma_px)
      : evaluator_(evaluator),
        vertex_ids_(vertex_ids),
        views_(views),
        inv_sigma_(1.0 / sigma_px),
        block_sizes_({3, evaluator.pose_dim(), evaluator.num_betas(), 3}) {
    for (const SilhouetteView& view : views_) {
      HL_CHECK(view.outline_px.size() == view.outline_normal.size() &&
                   view.outline_px.size() == view.outline_vertex.size(),
               "outline arrays differ in size");
    }
    set_num_residuals(evaluator.num_params() + 1);
    mutable_parameter_block_sizes()->assign(block_sizes_.begin(), block_sizes_.end());
  }
  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<int>& vertex_ids,
                                     const std::vector<SilhouetteView>& views,
                                     double sigma_px) {
    CheckOutlineVertices(views, vertex_ids.size());
    return new MultiViewSilhouetteSquareRootCost(evaluator, vertex_ids, views, sigma_px);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = evaluator_.num_params();
    const bool want_jac = jacobians != nullptr;
    const size_t nv = vertex_ids_.size();
    thread_local std::vector<double> vertices;
    vertices.resize(3 * nv);
    evaluator_.Vertices(parameters[0], parameters[1], parameters[2], parameters[3],
                        vertex_ids_, vertices.data());
    PointTermNormalEquations normal(static_cast<int>(nv));
    thread_local std::vector<Eigen::Vector2d> uv;
    thread_local std::vector<Eigen::Matrix<double, 2, 3>> d_uv;  // by the world point
    thread_local std::vector<char> valid;
    uv.resize(nv);
    d_uv.resize(nv);
    valid.resize(nv);
    for (const SilhouetteView& view : views_) {
      const Eigen::Matrix3d rot = view.camera.cam_from_world.rotation.toRotationMatrix();
      const Eigen::Vector3d& t = view.camera.cam_from_world.translation;
      for (size_t i = 0; i < nv; ++i) {
        const Eigen::Vector3d p =
            rot * Eigen::Map<const Eigen::Vector3d>(&vertices[3 * i]) + t;
        Eigen::Matrix<double, 2, 3> d_point;
        valid[i] = view.camera.camera.ProjectWithJacobian(p, &uv[i],
                                                          want_jac ? &d_point : nullptr);
        if (valid[i] && want_jac) d_uv[i].noalias() = d_point * rot;
      }
      for (size_t i = 0; i < nv; ++i) {
        if (!valid[i]) continue;
        Eigen::Vector2d gradient;
        const double d = DistanceWithGradient(view, uv[i], &gradient);
        if (!(d > view.inside_px)) continue;
        const double x = d - view.inside_px, cap = view.cap_px;
        // d r / d x: 1, or (cap / (cap + x))^2 when saturated.
        const double slope = view.one_sided ? std::pow(cap / (cap + x), 2) : 1.0;
        const double r = (view.one_sided ? cap * x / (cap + x) : x) * inv_sigma_;
        normal.AddRow(static_cast<int>(i), r,
                      want_jac ? Eigen::Vector3d(inv_sigma_ * slope *
                                                 d_uv[i].transpose() * gradient)
                               : Eigen::Vector3d::Zero());
      }
      for (size_t s = 0; s < view.outline_px.size(); ++s) {
        const int c = view.outline_vertex[s];
        if (c < 0 || !valid[c]) continue;
        const Eigen::Vector2d& nrm = view.outline_normal[s];
        const double r = nrm.dot(uv[c] - view.outline_px[s]) * inv_sigma_;
        if (view.one_sided && r > 0.0) continue;
        normal.AddRow(c, r,
                      want_jac ? Eigen::Vector3d(inv_sigma_ * d_uv[c].transpose() * nrm)
                               : Eigen::Vector3d::Zero());
      }
    }
    if (!want_jac) {
      WriteCostOnly(normal.squared_norm(), n + 1, residuals);
      return true;
    }
    const std::vector<int> used = normal.UsedPoints();
    std::vector<int> used_ids(used.size());
    for (size_t i = 0; i < used.size(); ++i) used_ids[i] = vertex_ids_[used[i]];
    thread_local std::vector<double> used_xyz, used_jac;
    used_xyz.resize(3 * used.size());
    used_jac.resize(3 * used.size() * n);
    evaluator_.VerticesAndJacobian(parameters[0], parameters[1], parameters[2],
                                   parameters[3], used_ids, used_xyz.data(),
                                   used_jac.data());
    normal.WriteCeresOutput(used_jac.data(), n, block_sizes_, residuals, jacobians);
    return true;
  }

 private:
  const HandEvaluator& evaluator_;
  std::vector<int> vertex_ids_;
  const std::vector<SilhouetteView>& views_;
  double inv_sigma_;
  std::vector<int> block_sizes_;
};

}  // namespace handlabel
