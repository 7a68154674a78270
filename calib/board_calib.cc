#include "calib/board_calib.h"

#include <algorithm>
#include <cmath>

#include "calib/board_calib_init.h"
#include "calib/board_corner_cost.h"
#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

// The optimised state, laid out as Ceres parameter blocks.
struct Pose {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // coeffs x, y, z, w
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Pose() = default;
  explicit Pose(const Rigid3& r) : q(r.rotation), t(r.translation) {}
  Rigid3 ToRigid() const { return Rigid3(q, t); }
};

struct Observation {
  int camera;
  std::string frame;
  int corner_id;
  Eigen::Vector2d pixel;
  bool inlier = true;
};

struct State {
  std::vector<std::vector<double>> intrinsics;
  std::vector<Pose> cam_from_world;
  std::map<std::string, Pose> world_from_board;
};

Eigen::Vector2d Residual(const State& s, const std::vector<CameraModelId>& models,
                         const BoardSpec& board, const Observation& o, bool* ok) {
  const BoardCornerCost cost(models[o.camera], board.Corner(o.corner_id), o.pixel);
  const Pose& cam = s.cam_from_world[o.camera];
  const Pose& b = s.world_from_board.at(o.frame);
  Eigen::Vector2d r;
  *ok = cost(s.intrinsics[o.camera].data(), cam.q.coeffs().data(), cam.t.data(),
             b.q.coeffs().data(), b.t.data(), r.data());
  return r;
}

void Solve(State* s, const std::vector<CameraModelId>& models, const BoardSpec& board,
           const std::vector<Observation>& observations, size_t master,
           const BoardCalibOptions& options) {
  ceres::Problem problem;
  for (const Observation& o : observations) {
    if (!o.inlier) continue;
    Pose& cam = s->cam_from_world[o.camera];
    Pose& b = s->world_from_board.at(o.frame);
    problem.AddResidualBlock(
        BoardCornerCost::Create(models[o.camera], board.Corner(o.corner_id), o.pixel),
        new ceres::HuberLoss(options.huber_px), s->intrinsics[o.camera].data(),
        cam.q.coeffs().data(), cam.t.data(), b.q.coeffs().data(), b.t.data());
  }
  for (size_t c = 0; c < s->cam_from_world.size(); ++c) {
    Pose& cam = s->cam_from_world[c];
    if (!problem.HasParameterBlock(cam.q.coeffs().data())) continue;
    problem.SetManifold(cam.q.coeffs().data(), new ceres::EigenQuaternionManifold);
    if (c == master) {  // the gauge: the master camera is the world during the solve
      problem.SetParameterBlockConstant(cam.q.coeffs().data());
      problem.SetParameterBlockConstant(cam.t.data());
    }
  }
  for (auto& [key, b] : s->world_from_board) {
    if (problem.HasParameterBlock(b.q.coeffs().data())) {
      problem.SetManifold(b.q.coeffs().data(), new ceres::EigenQuaternionManifold);
    }
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.num_threads;
  solver.function_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    throw InputError("board calibration", "bundle adjustment", "a usable solution",
                     summary.message);
  }
}

}  // namespace

void BoardCalibOptions::Check(const std::string& source) const {
  RequireGreater(source, "huber_px", huber_px, 0);
  RequireAtLeast(source, "outlier_rounds", outlier_rounds, 0);
  RequireGreater(source, "outlier_sigmas", outlier_sigmas, 0);
  RequireGreater(source, "min_outlier_px", min_outlier_px, 0);
  RequireAtLeast(source, "min_frames_per_camera", min_frames_per_camera, 1);
  RequireAtLeast(source, "max_iterations", max_iterations, 1);
  RequireAtLeast(source, "num_threads", num_threads, 1);
  if (world != "camera" && world != "board" && world.rfind("board:", 0) != 0) {
    throw InputError(source, "world", "camera, board or board:FRAME", "'" + world + "'");
  }
}

namespace {

// The master camera's index: options.master by name, else the first camera.
size_t MasterIndex(const std::vector<CameraBoardViews>& views,
                   const BoardCalibOptions& options) {
  if (options.master.empty()) return 0;
  const auto it =
      std::find_if(views.begin(), views.end(),
                   [&](const CameraBoardViews& v) { return v.name == options.master; });
  if (it == views.end()) {
    std::string known;
    for (const auto& v : views) known += (known.empty() ? "" : ", ") + v.name;
    throw InputError("--master", "camera", "one of [" + known + "]",
                     "'" + options.master + "'");
  }
  return static_cast<size_t>(it - views.begin());
}

void CheckEnoughFrames(const std::vector<CameraBoardViews>& views,
                       const BoardCalibOptions& options) {
  for (const CameraBoardViews& v : views) {
    if (static_cast<int>(v.frames.size()) < options.min_frames_per_camera) {
      throw InputError("camera " + v.name, "board detections",
                       "at least " + std::to_string(options.min_frames_per_camera) +
                           " images with the board found",
                       std::to_string(v.frames.size()));
    }
  }
}

// Steps 1-2 as the solver's start: per-camera intrinsics, chained extrinsics, and each
// frame's board pose from the camera that saw most of it.
State InitialState(const std::vector<CameraBoardViews>& views,
                   const std::vector<InitialCamera>& initial,
                   const std::vector<Rigid3>& cam_from_master) {
  State state;
  for (size_t c = 0; c < views.size(); ++c) {
    state.intrinsics.push_back(initial[c].camera.params());
    state.cam_from_world.emplace_back(cam_from_master[c]);
  }
  std::map<std::string, std::pair<size_t, size_t>> best_view;  // key -> (corners, camera)
  for (size_t c = 0; c < views.size(); ++c) {
    for (const auto& [key, pose] : initial[c].cam_from_board) {
      auto& best = best_view[key];
      if (views[c].frames.at(key).size() > best.first)
        best = {views[c].frames.at(key).size(), c};
    }
  }
  for (const auto& [key, best] : best_view) {
    const size_t c = best.second;
    state.world_from_board[key] =
        Pose(cam_from_master[c].Inverse() * initial[c].cam_from_board.at(key));
  }
  return state;
}

// Every corner seen in a frame that has an initial board pose.
std::vector<Observation> CollectObservations(const std::vector<CameraBoardViews>& views,
                                             const State& state) {
  std::vector<Observation> observations;
  for (size_t c = 0; c < views.size(); ++c) {
    for (const auto& [key, obs] : views[c].frames) {
      if (!state.world_from_board.count(key)) continue;  // no usable initial board pose
      for (size_t i = 0; i < obs.size(); ++i) {
        observations.push_back({static_cast<int>(c), key, obs.ids[i], obs.pixels[i]});
      }
    }
  }
  return observations;
}

// Step 3: bundle adjustment, then rounds of outlier rejection, each followed by a new
// solve, until no observation changes its inlier state.
void SolveWithOutlierRounds(State* state, const std::vector<CameraModelId>& models,
                            const BoardSpec& board,
                            std::vector<Observation>* observations, size_t master,
                            const BoardCalibOptions& options) {
  Solve(state, models, board, *observations, master, options);
  for (int round = 0; round < options.outlier_rounds; ++round) {
    std::vector<double> norms;
    for (const Observation& o : *observations) {
      bool ok;
      if (o.inlier) norms.push_back(Residual(*state, models, board, o, &ok).norm());
    }
    std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
    // For 2D Gaussian residuals, median |r| = 1.1774 sigma.
    const double sigma = norms[norms.size() / 2] / 1.1774;
    const double threshold =
        std::max(options.min_outlier_px, options.outlier_sigmas * sigma);
    int changed = 0;
    for (Observation& o : *observations) {
      bool ok;
      const double r = Residual(*state, models, board, o, &ok).norm();
      const bool inlier = ok && r <= threshold;
      if (inlier != o.inlier) ++changed;
      o.inlier = inlier;
    }
    if (changed == 0) break;
    Solve(state, models, board, *observations, master, options);
  }
}

// Step 4: the world frame (master camera or the board in one frame) as master_from_world;
// `world` receives its description.
Rigid3 MasterFromWorld(const std::vector<CameraBoardViews>& views, size_t master,
                       const State& state, const BoardCalibOptions& options,
                       std::string* world) {
  *world = "camera:" + views[master].name;
  if (options.world == "camera") return Rigid3();  // identity: world = master camera
  std::string key;
  if (options.world == "board") {
    key = views[master].frames.begin()->first;
  } else {
    key = options.world.substr(6);
    if (!state.world_from_board.count(key)) {
      throw InputError("--world", "board:FRAME",
                       "a frame in which some camera saw the board", "'" + key + "'");
    }
  }
  *world = "board:" + key;
  return state.world_from_board.at(key).ToRigid();
}

// The solved cameras and board poses, re-expressed in the world frame.
void AddRigAndBoards(const std::vector<CameraBoardViews>& views,
                     const std::vector<CameraModelId>& models, const State& state,
                     const Rigid3& master_from_world, BoardCalibResult* result) {
  for (size_t c = 0; c < views.size(); ++c) {
    RigCamera rc;
    rc.name = views[c].name;
    rc.camera = Camera(models[c], views[c].width, views[c].height, state.intrinsics[c],
                       "calibrated camera " + views[c].name);
    rc.cam_from_world = state.cam_from_world[c].ToRigid() * master_from_world;
    result->rig.Add(rc);
  }
  for (const auto& [key, pose] : state.world_from_board) {
    result->world_from_board[key] = master_from_world.Inverse() * pose.ToRigid();
  }
}

// Per-camera and overall statistics and every corner's final residual.
void AddStatistics(const std::vector<CameraBoardViews>& views,
                   const std::vector<InitialCamera>& initial,
                   const std::vector<CameraModelId>& models, const BoardSpec& board,
                   const State& state, const std::vector<Observation>& observations,
                   BoardCalibResult* result) {
  result->stats.resize(views.size());
  std::vector<double> sum_sq(views.size(), 0.0);
  double total_sq = 0;
  int total = 0;
  for (size_t c = 0; c < views.size(); ++c) {
    result->stats[c].name = views[c].name;
    result->stats[c].frames = static_cast<int>(views[c].frames.size());
    result->stats[c].initial_rms_px = initial[c].rms_px;
  }
  for (const Observation& o : observations) {
    bool ok;
    const Eigen::Vector2d r = Residual(state, models, board, o, &ok);
    result->residuals.push_back({o.camera, o.frame, o.corner_id, o.pixel, r, o.inlier});
    CameraCalibStats& st = result->stats[o.camera];
    if (o.inlier) {
      ++st.observations;
      sum_sq[o.camera] += r.squaredNorm();
      total_sq += r.squaredNorm();
      ++total;
    } else {
      ++st.outliers;
    }
  }
  for (size_t c = 0; c < views.size(); ++c) {
    const int n = result->stats[c].observations;
    result->stats[c].rms_px = n > 0 ? std::sqrt(sum_sq[c] / n) : 0;
  }
  result->rms_px = total > 0 ? std::sqrt(total_sq / total) : 0;
}

}  // namespace

BoardCalibResult CalibrateBoardRig(const std::vector<CameraBoardViews>& views,
                                   const BoardSpec& board,
                                   const BoardCalibOptions& options) {
  options.Check("BoardCalibOptions");
  board.Check("board");
  if (views.empty())
    throw InputError("board calibration", "cameras", "at least one camera");
  const size_t master = MasterIndex(views, options);
  CheckEnoughFrames(views, options);

  BoardCalibResult result;
  std::vector<InitialCamera> initial;
  for (const CameraBoardViews& v : views) {
    initial.push_back(InitialIntrinsics(v, board, options.model));
  }
  const std::vector<Rigid3> cam_from_master =
      ChainExtrinsics(views, initial, master, &result.tree);
  State state = InitialState(views, initial, cam_from_master);
  const std::vector<CameraModelId> models(views.size(), options.model);
  std::vector<Observation> observations = CollectObservations(views, state);

  SolveWithOutlierRounds(&state, models, board, &observations, master, options);

  const Rigid3 master_from_world =
      MasterFromWorld(views, master, state, options, &result.world);
  AddRigAndBoards(views, models, state, master_from_world, &result);
  AddStatistics(views, initial, models, board, state, observations, &result);
  return result;
}

}  // namespace handlabel
