#include "hand/detector_keypoints.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/data_dir.h"
#include "core/errors.h"
#include "core/json_util.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "handlabel-detector-keypoints";
constexpr int kVersion = 1;

// One keypoint's least squares: rows 3 per used sample, A = V_i - K, b = X - K.
struct KeypointSystem {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
};

KeypointSystem BuildSystem(const std::vector<HandMesh>& meshes,
                           const std::vector<DetectorKeypointSample>& samples,
                           const std::vector<int>& used, int k,
                           const std::vector<int>& ids) {
  KeypointSystem s;
  s.a.resize(3 * used.size(), ids.size());
  s.b.resize(3 * used.size());
  for (size_t r = 0; r < used.size(); ++r) {
    const HandMesh& mesh = meshes[used[r]];
    const Eigen::RowVector3d own = mesh.keypoints.row(k);
    for (size_t i = 0; i < ids.size(); ++i) {
      s.a.block(3 * r, i, 3, 1) = (mesh.vertices.row(ids[i]) - own).transpose();
    }
    s.b.segment(3 * r, 3) = (samples[used[r]].detected.row(k) - own).transpose();
  }
  return s;
}

Eigen::VectorXd SolveRidge(const KeypointSystem& s, double ridge) {
  Eigen::MatrixXd normal = s.a.transpose() * s.a;
  const double scale = normal.trace() / std::max<Eigen::Index>(1, normal.rows());
  normal.diagonal().array() += ridge * scale + 1e-18;
  return normal.ldlt().solve(s.a.transpose() * s.b);
}

// Residual distance per used sample of the weights `w`.
std::vector<double> SampleResiduals(const KeypointSystem& s, const Eigen::VectorXd& w) {
  const Eigen::VectorXd r = s.a * w - s.b;
  std::vector<double> out(r.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = r.segment(3 * i, 3).norm();
  return out;
}

double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::vector<int> DetectorKeypointModel::AllVertexIds() const {
  std::vector<int> ids;
  for (const std::vector<int>& v : vertices) ids.insert(ids.end(), v.begin(), v.end());
  return ids;
}

void DetectorKeypointModel::Check(const std::string& source, int model_vertices) const {
  if (num_vertices != model_vertices) {
    throw InputError(source, "num_vertices",
                     "the hand model's vertex count " + std::to_string(model_vertices),
                     std::to_string(num_vertices));
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const std::string field = "keypoints[" + std::to_string(k) + "]";
    if (vertices[k].size() != weights[k].size()) {
      throw InputError(source, field, "as many weights as vertices",
                       std::to_string(weights[k].size()) + " weights, " +
                           std::to_string(vertices[k].size()) + " vertices");
    }
    for (int v : vertices[k]) {
      if (v < 0 || v >= num_vertices) {
        throw InputError(source, field + ".vertices",
                         "ids in [0, " + std::to_string(num_vertices) + ")",
                         std::to_string(v));
      }
    }
  }
}

void DetectorKeypointsAndJacobian(const HandEvaluator& evaluator,
                                  const DetectorKeypointModel& model,
                                  const std::vector<int>& vertex_ids,
                                  const double* global_orient, const double* hand_pose,
                                  const double* betas, const double* transl,
                                  double* keypoints63, double* jacobian) {
  const int n = evaluator.num_params();
  thread_local std::vector<double> kp, kp_jac, v, v_jac;
  kp.resize(3 * kNumHandKeypoints);
  kp_jac.resize(3 * kNumHandKeypoints * n);
  v.resize(3 * vertex_ids.size());
  v_jac.resize(3 * vertex_ids.size() * n);
  evaluator.KeypointsAndJacobian(global_orient, hand_pose, betas, transl, kp.data(),
                                 kp_jac.data());
  evaluator.VerticesAndJacobian(global_orient, hand_pose, betas, transl, vertex_ids,
                                v.data(), v_jac.data());
  ApplyDetectorKeypoints(model, kp.data(), v.data(), 1, keypoints63);
  ApplyDetectorKeypoints(model, kp_jac.data(), v_jac.data(), n, jacobian);
}

Points3d DetectorKeypointsOfMesh(const DetectorKeypointModel& model,
                                 const HandMesh& mesh) {
  const std::vector<int> ids = model.AllVertexIds();
  Points3d vertices(ids.size(), 3);
  for (size_t i = 0; i < ids.size(); ++i) vertices.row(i) = mesh.vertices.row(ids[i]);
  Points3d out(kNumHandKeypoints, 3);
  ApplyDetectorKeypoints(model, mesh.keypoints.data(), vertices.data(), 1, out.data());
  return out;
}

std::array<std::vector<int>, kNumHandKeypoints> NearestVertexIds(const HandModel& model,
                                                                 int count) {
  const HandMesh rest = PoseHand(model, HandParams());
  std::array<std::vector<int>, kNumHandKeypoints> nearest;
  const int n = static_cast<int>(rest.vertices.rows());
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<int> ids(n);
    for (int v = 0; v < n; ++v) ids[v] = v;
    const Eigen::RowVector3d at = rest.keypoints.row(k);
    const int m = std::min(count, n);
    // Ties broken by id, so the choice does not depend on the sort's implementation.
    std::partial_sort(ids.begin(), ids.begin() + m, ids.end(), [&](int a, int b) {
      const double da = (rest.vertices.row(a) - at).squaredNorm();
      const double db = (rest.vertices.row(b) - at).squaredNorm();
      return da < db || (da == db && a < b);
    });
    nearest[k].assign(ids.begin(), ids.begin() + m);
  }
  return nearest;
}

void LearnDetectorKeypointsOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "vertices_per_keypoint", vertices_per_keypoint, 1);
  RequireAtLeast(source, "ridge", ridge, 0.0);
  RequireGreater(source, "outlier_factor", outlier_factor, 1.0);
}

DetectorKeypointModel LearnDetectorKeypoints(
    const HandModel& hand_model, const std::vector<DetectorKeypointSample>& samples,
    const LearnDetectorKeypointsOptions& options, const std::string& detector,
    const std::string& learned) {
  options.Check("LearnDetectorKeypointsOptions");
  DetectorKeypointModel model;
  model.detector = detector;
  model.learned = learned;
  model.num_vertices = hand_model.num_vertices();
  model.vertices = NearestVertexIds(hand_model, options.vertices_per_keypoint);
  std::vector<HandMesh> meshes;
  for (const DetectorKeypointSample& s : samples) {
    meshes.push_back(PoseHand(hand_model, s.truth));
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<int> used;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (samples[i].found[k]) used.push_back(static_cast<int>(i));
    }
    if (used.size() < 4) {
      throw InputError("detector keypoint samples", "keypoint " + std::to_string(k),
                       "found in at least 4 frames", std::to_string(used.size()));
    }
    const KeypointSystem first = BuildSystem(meshes, samples, used, k, model.vertices[k]);
    const Eigen::VectorXd w0 = SolveRidge(first, options.ridge);
    const std::vector<double> residuals = SampleResiduals(first, w0);
    const double limit = options.outlier_factor * Median(residuals);
    std::vector<int> kept;
    for (size_t i = 0; i < used.size(); ++i) {
      if (residuals[i] <= limit) kept.push_back(used[i]);
    }
    const Eigen::VectorXd w = SolveRidge(
        BuildSystem(meshes, samples, kept, k, model.vertices[k]), options.ridge);
    model.weights[k].assign(w.data(), w.data() + w.size());
  }
  return model;
}

void WriteDetectorKeypointModel(const std::string& path,
                                const DetectorKeypointModel& model) {
  json keypoints = json::array();
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    keypoints.push_back({{"vertices", model.vertices[k]}, {"weights", model.weights[k]}});
  }
  const json out = {{"format", kFormat},
                    {"version", kVersion},
                    {"detector", model.detector},
                    {"learned", model.learned},
                    {"num_vertices", model.num_vertices},
                    {"keypoints", keypoints}};
  WriteFileAtomically(path, out.dump(1) + "\n");
}

DetectorKeypointModel ReadDetectorKeypointModel(const std::string& path) {
  const json in = ReadJsonFileStrict(path);
  RejectUnknownKeys(
      in, {"format", "version", "detector", "learned", "num_vertices", "keypoints"},
      path);
  if (JsonString(in, "format", path) != kFormat) {
    throw InputError(path, "format", kFormat, JsonString(in, "format", path));
  }
  const int version =
      static_cast<int>(JsonNumber(JsonMember(in, "version", path), path, "version"));
  if (version != kVersion) {
    throw InputError(path, "version", std::to_string(kVersion), std::to_string(version));
  }
  DetectorKeypointModel model;
  model.detector = JsonString(in, "detector", path);
  model.learned = JsonString(in, "learned", path);
  model.num_vertices = static_cast<int>(
      JsonNumber(JsonMember(in, "num_vertices", path), path, "num_vertices"));
  const json& keypoints = JsonMember(in, "keypoints", path);
  if (!keypoints.is_array() || keypoints.size() != kNumHandKeypoints) {
    throw InputError(path, "keypoints", "an array of 21 entries", keypoints.dump());
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const std::string where = "keypoints[" + std::to_string(k) + "].";
    RejectUnknownKeys(keypoints[k], {"vertices", "weights"}, path, where);
    const Eigen::VectorXd ids = JsonVector(
        JsonMember(keypoints[k], "vertices", path, where), path, where + "vertices", -1);
    const Eigen::VectorXd w = JsonVector(JsonMember(keypoints[k], "weights", path, where),
                                         path, where + "weights", -1);
    for (Eigen::Index i = 0; i < ids.size(); ++i) {
      if (ids[i] != std::floor(ids[i])) {
        throw InputError(path, where + "vertices", "integer vertex ids",
                         std::to_string(ids[i]));
      }
      model.vertices[k].push_back(static_cast<int>(ids[i]));
    }
    model.weights[k].assign(w.data(), w.data() + w.size());
  }
  model.Check(path, model.num_vertices);
  return model;
}

std::optional<DetectorKeypointModel> DetectorKeypointModelOfSetting(
    const std::string& setting, const std::string& source, const std::string& field) {
  if (setting == "none") return std::nullopt;
  const std::string path = setting == "mediapipe"
                               ? ShippedModelPath("detector_keypoints_mediapipe.json")
                               : setting;
  if (!std::filesystem::exists(path)) {
    throw InputError(source, field,
                     "none, mediapipe or an existing detector keypoint model file",
                     setting + " (" + path + " does not exist)");
  }
  return ReadDetectorKeypointModel(path);
}

}  // namespace handlabel
