#include "calib/board_calib_init.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <set>

#include "calib/board_corner_cost.h"
#include "core/errors.h"

namespace handlabel {
namespace {

Rigid3 RigidFromRodrigues(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rotation;
  cv::cv2eigen(r, rotation);
  return Rigid3(
      Eigen::Quaterniond(rotation),
      Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
}

// The requested model's parameters for a pinhole camera without distortion.
std::vector<double> PinholeParams(CameraModelId model, double f, double cx, double cy) {
  std::vector<double> p(NumCameraParams(model), 0.0);
  switch (model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kSimpleRadial:
    case CameraModelId::kRadial:
      p[0] = f;
      p[1] = cx;
      p[2] = cy;
      break;
    default:
      p[0] = p[1] = f;
      p[2] = cx;
      p[3] = cy;
  }
  return p;
}

// One camera's board corners as OpenCV point lists, one list per frame (frame order).
struct CornerLists {
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
};

CornerLists ToCornerLists(const CameraBoardViews& views, const BoardSpec& board) {
  CornerLists lists;
  for (const auto& [key, obs] : views.frames) {
    std::vector<cv::Point3f> object;
    std::vector<cv::Point2f> image;
    for (size_t i = 0; i < obs.size(); ++i) {
      const Eigen::Vector3d c = board.Corner(obs.ids[i]);
      object.emplace_back(c.x(), c.y(), c.z());
      image.emplace_back(obs.pixels[i].x(), obs.pixels[i].y());
    }
    lists.object_points.push_back(object);
    lists.image_points.push_back(image);
  }
  return lists;
}

// OpenCV's homography estimate first (principal point at the image centre, skipped
// when OpenCV fails), then a range of guesses relative to the image size.
std::vector<double> FocalGuesses(const CameraBoardViews& views,
                                 const CornerLists& lists) {
  std::vector<double> guesses;
  try {
    const cv::Mat k = cv::initCameraMatrix2D(lists.object_points, lists.image_points,
                                             cv::Size(views.width, views.height), 1.0);
    guesses.push_back(0.5 * (k.at<double>(0, 0) + k.at<double>(1, 1)));
  } catch (const cv::Exception&) {
  }
  for (double scale : {0.4, 0.6, 0.8, 1.0, 1.3, 1.7, 2.2, 3.0}) {
    guesses.push_back(scale * std::max(views.width, views.height));
  }
  return guesses;
}

// Board poses by planar PnP of every view for a pinhole camera of focal length f and
// principal point (cx, cy), with the median reprojection error over all corners.
std::map<std::string, Rigid3> PlanarPoses(const CameraBoardViews& views,
                                          const CornerLists& lists, double f, double cx,
                                          double cy, double* median_error) {
  const cv::Mat kk = (cv::Mat_<double>(3, 3) << f, 0, cx, 0, f, cy, 0, 0, 1);
  std::map<std::string, Rigid3> poses;
  std::vector<double> errors;
  size_t i = 0;
  for (const auto& [key, obs] : views.frames) {
    const std::vector<cv::Point3f>& object = lists.object_points[i];
    const std::vector<cv::Point2f>& image = lists.image_points[i];
    ++i;
    cv::Mat rvec, tvec;
    const bool solved =
        object.size() >= 4 && cv::solvePnP(object, image, kk, cv::noArray(), rvec, tvec,
                                           false, cv::SOLVEPNP_IPPE);
    if (!solved || !cv::checkRange(rvec) || !cv::checkRange(tvec) ||
        tvec.at<double>(2) <= 0) {
      continue;  // a degenerate view (e.g. corners on one line): not used to initialise
    }
    std::vector<cv::Point2f> projected;
    cv::projectPoints(object, rvec, tvec, kk, cv::noArray(), projected);
    for (size_t j = 0; j < projected.size(); ++j) {
      errors.push_back(cv::norm(projected[j] - image[j]));
    }
    const Rigid3 pose = RigidFromRodrigues(rvec, tvec);
    bool in_front = true;
    for (const cv::Point3f& p : object) {
      in_front = in_front && (pose * Eigen::Vector3d(p.x, p.y, p.z)).z() > 1e-6;
    }
    if (in_front) poses[key] = pose;
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  *median_error = errors.empty() ? 1e30 : errors[errors.size() / 2];
  return poses;
}

// The guess with the smallest median PnP error; 0 if none is usable.
double ChooseFocal(const CameraBoardViews& views, const CornerLists& lists, double cx,
                   double cy) {
  double f = 0, best_error = std::numeric_limits<double>::infinity();
  for (double guess : FocalGuesses(views, lists)) {
    if (!std::isfinite(guess) || guess <= 0) continue;
    double error;
    PlanarPoses(views, lists, guess, cx, cy, &error);
    if (error < best_error) {
      best_error = error;
      f = guess;
    }
    // OpenCV's estimate (tried first) is good enough unless lenses are far from
    // pinhole: skip the search.
    if (best_error < 5.0) break;
  }
  return f;
}

using BoardPoses = std::map<std::string, std::pair<Eigen::Quaterniond, Eigen::Vector3d>>;

// Per-camera bundle adjustment of the intrinsics and the board poses (the camera is
// the world). Throws InputError naming the camera if Ceres finds no usable solution.
void AdjustCamera(const CameraBoardViews& views, const BoardSpec& board,
                  CameraModelId model, const std::string& source, const char* expected,
                  std::vector<double>* params, BoardPoses* poses) {
  ceres::Problem problem;
  Eigen::Quaterniond identity_q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d zero_t = Eigen::Vector3d::Zero();
  for (const auto& [key, obs] : views.frames) {
    if (!poses->count(key)) continue;
    auto& pose = (*poses)[key];
    for (size_t j = 0; j < obs.size(); ++j) {
      problem.AddResidualBlock(
          BoardCornerCost::Create(model, board.Corner(obs.ids[j]), obs.pixels[j]),
          new ceres::HuberLoss(1.0), params->data(), identity_q.coeffs().data(),
          zero_t.data(), pose.first.coeffs().data(), pose.second.data());
    }
    problem.SetManifold(pose.first.coeffs().data(), new ceres::EigenQuaternionManifold);
  }
  problem.SetParameterBlockConstant(identity_q.coeffs().data());
  problem.SetParameterBlockConstant(zero_t.data());
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;
  solver.max_num_iterations = 100;
  solver.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    throw InputError(source, "board detections", expected, summary.message);
  }
}

// Stores the adjusted board poses in `out` and sets its reprojection RMS.
void StorePosesAndRms(const CameraBoardViews& views, const BoardSpec& board,
                      const BoardPoses& poses, InitialCamera* out) {
  double sum_sq = 0;
  int count = 0;
  for (const auto& [key, obs] : views.frames) {
    if (!poses.count(key)) continue;
    const Rigid3 pose(poses.at(key).first, poses.at(key).second);
    out->cam_from_board[key] = pose;
    for (size_t j = 0; j < obs.size(); ++j) {
      Eigen::Vector2d uv;
      if (out->camera.Project(pose * board.Corner(obs.ids[j]), &uv)) {
        sum_sq += (uv - obs.pixels[j]).squaredNorm();
        ++count;
      }
    }
  }
  out->rms_px = count > 0 ? std::sqrt(sum_sq / count) : 0;
}

}  // namespace

InitialCamera InitialIntrinsics(const CameraBoardViews& views, const BoardSpec& board,
                                CameraModelId model) {
  const CornerLists lists = ToCornerLists(views, board);
  const std::string source = "camera " + views.name;
  const char* expected = "board views that constrain the focal length (several tilts)";
  // Focal length: OpenCV's homography estimate (principal point at the image centre)
  // when it is usable, else the best of a range of guesses, judged by the median
  // reprojection error after planar PnP of every view; then board poses by planar PnP
  // and a per-camera bundle adjustment.
  const double cx = (views.width - 1) / 2.0, cy = (views.height - 1) / 2.0;
  const double f = ChooseFocal(views, lists, cx, cy);
  if (f <= 0)
    throw InputError(source, "board detections", expected, "no focal length estimate");
  std::vector<double> params = PinholeParams(model, f, cx, cy);
  BoardPoses poses;
  double unused;
  for (const auto& [key, pose] : PlanarPoses(views, lists, f, cx, cy, &unused)) {
    poses[key] = {pose.rotation, pose.translation};
  }
  AdjustCamera(views, board, model, source, expected, &params, &poses);
  InitialCamera out;
  out.camera = Camera(model, views.width, views.height, params, source);
  StorePosesAndRms(views, board, poses, &out);
  return out;
}

Rigid3 MedoidPose(const std::vector<Rigid3>& poses, double scale) {
  HL_CHECK(!poses.empty(), "medoid of no poses");
  size_t best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poses.size(); ++i) {
    double cost = 0;
    for (size_t j = 0; j < poses.size(); ++j) {
      cost += RotationAngleBetween(poses[i], poses[j]) +
              (poses[i].translation - poses[j].translation).norm() / scale;
    }
    if (cost < best_cost) {
      best_cost = cost;
      best = i;
    }
  }
  return poses[best];
}

std::vector<Rigid3> ChainExtrinsics(
    const std::vector<CameraBoardViews>& views, const std::vector<InitialCamera>& initial,
    size_t master, std::vector<std::tuple<std::string, std::string, int>>* tree) {
  const size_t n = views.size();
  // Edge weights: corners seen by both cameras in shared frames.
  std::vector<std::vector<int>> weight(n, std::vector<int>(n, 0));
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a + 1; b < n; ++b) {
      for (const auto& [key, obs] : views[a].frames) {
        const auto it = views[b].frames.find(key);
        if (it == views[b].frames.end()) continue;
        const int shared = static_cast<int>(std::min(obs.size(), it->second.size()));
        weight[a][b] += shared;
        weight[b][a] += shared;
      }
    }
  }
  // Prim's algorithm for a maximum spanning tree from the master camera.
  std::vector<Rigid3> cam_from_master(n);
  std::vector<bool> in_tree(n, false);
  in_tree[master] = true;
  double scale = 0;  // typical board distance, for the medoid's translation units
  for (const auto& [key, pose] : initial[master].cam_from_board)
    scale += pose.translation.norm();
  scale =
      std::max(1e-3, scale / std::max<size_t>(1, initial[master].cam_from_board.size()));
  for (size_t added = 1; added < n; ++added) {
    int best = 0;
    size_t parent = 0, child = 0;
    for (size_t a = 0; a < n; ++a) {
      if (!in_tree[a]) continue;
      for (size_t b = 0; b < n; ++b) {
        if (!in_tree[b] && weight[a][b] > best) {
          best = weight[a][b];
          parent = a;
          child = b;
        }
      }
    }
    if (best == 0) {
      std::string missing, linked;
      for (size_t i = 0; i < n; ++i) {
        std::string& list = in_tree[i] ? linked : missing;
        list += (list.empty() ? "" : ", ") + views[i].name;
      }
      throw InputError(
          "camera graph", "shared board views",
          "every camera linked to the master through frames where two cameras "
          "see the board at the same time",
          "cameras [" + missing + "] cannot be linked to [" + linked + "]");
    }
    std::vector<Rigid3> candidates;  // child_from_parent per shared frame
    for (const auto& [key, parent_pose] : initial[parent].cam_from_board) {
      const auto it = initial[child].cam_from_board.find(key);
      if (it != initial[child].cam_from_board.end()) {
        candidates.push_back(it->second * parent_pose.Inverse());
      }
    }
    cam_from_master[child] = MedoidPose(candidates, scale) * cam_from_master[parent];
    in_tree[child] = true;
    if (tree) tree->emplace_back(views[parent].name, views[child].name, best);
  }
  return cam_from_master;
}

}  // namespace handlabel
