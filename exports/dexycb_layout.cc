#include "exports/dexycb_layout.h"

#include <Eigen/LU>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "formats/npz.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

constexpr char kCalibrationId[] = "handlabel";  // extrinsics_<id>, mano_<id>
constexpr char kSubject[] = "handlabel";

std::string Number(double v) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

// A YAML flow list of numbers.
std::string NumberList(const double* v, int n) {
  std::string out = "[";
  for (int i = 0; i < n; ++i) out += (i ? ", " : "") + Number(v[i]);
  return out + "]";
}

// A quoted YAML scalar (JSON strings are YAML strings): serials stay strings.
std::string Quoted(const std::string& text) { return nlohmann::json(text).dump(); }

// 45 PCA coefficients c with hand_pose = hands_mean + components^T c (manopth's
// use_pca=True, ncomps=45, flat_hand_mean=False; rows of pose_pca_basis are the
// components).
class PcaPose {
 public:
  explicit PcaPose(const HandModel& model) : mean_(model.pose_mean) {
    if (model.pose_pca_basis.rows() != kNumPoseParams ||
        model.pose_pca_basis.cols() != kNumPoseParams ||
        model.pose_mean.size() != kNumPoseParams) {
      throw InputError(model.name, "hands_components / hands_mean",
                       "45 x 45 pose PCA components and a 45-value hands_mean "
                       "(DexYCB's pose_m holds 45 PCA coefficients)",
                       std::to_string(model.pose_pca_basis.rows()) + " components");
    }
    lu_.compute(model.pose_pca_basis.transpose());
    if (!lu_.isInvertible()) {
      throw InputError(model.name, "hands_components", "45 independent components",
                       "rank " + std::to_string(lu_.rank()));
    }
  }
  Eigen::VectorXd Coefficients(const Eigen::VectorXd& hand_pose) const {
    return lu_.solve(hand_pose - mean_);
  }

 private:
  Eigen::VectorXd mean_;
  Eigen::FullPivLU<Eigen::MatrixXd> lu_;
};

void WriteCalibration(const fs::path& root, const Rig& rig,
                      const Eigen::VectorXd& betas) {
  const fs::path calib = root / "calibration";
  std::string extrinsics = "extrinsics:\n";
  for (const RigCamera& camera : rig.cameras()) {
    const Eigen::Vector4d k = PinholeIntrinsics(camera, "DexYCB");
    WriteFileAtomically((calib / "intrinsics" /
                         (camera.name + "_" + std::to_string(camera.camera.width()) +
                          "x" + std::to_string(camera.camera.height()) + ".yml"))
                            .string(),
                        "color:\n  fx: " + Number(k[0]) + "\n  fy: " + Number(k[1]) +
                            "\n  ppx: " + Number(k[2]) + "\n  ppy: " + Number(k[3]) +
                            "\n");
    // Row-major 3x4 camera -> common (world).
    const Matrix3x4d m = camera.cam_from_world.Inverse().ToMatrix();
    double row_major[12];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) row_major[4 * r + c] = m(r, c);
    }
    extrinsics += "  " + Quoted(camera.name) + ": " + NumberList(row_major, 12) + "\n";
  }
  extrinsics += "master: " + Quoted(rig[0].name) + "\n";
  WriteFileAtomically(
      (calib / (std::string("extrinsics_") + kCalibrationId) / "extrinsics.yml").string(),
      extrinsics);
  WriteFileAtomically(
      (calib / (std::string("mano_") + kCalibrationId) / "mano.yml").string(),
      "betas: " + NumberList(betas.data(), static_cast<int>(betas.size())) + "\n");
}

void WriteMeta(const fs::path& sequence, const LabelSeries& series, const Rig& rig) {
  std::ostringstream meta;
  meta << "serials:\n";
  for (const RigCamera& camera : rig.cameras())
    meta << "- " << Quoted(camera.name) << "\n";
  meta << "num_frames: " << series.labels.size() << "\n"
       << "ycb_ids: []\nycb_grasp_ind: null\n"
       << "mano_sides:\n- " << HandSideName(series.side) << "\n"
       << "mano_calib:\n- " << kCalibrationId << "\n"
       << "extrinsics: " << kCalibrationId << "\n"
       << "handlabel_labels: " << Quoted(series.labels_dir) << "\n"
       << "handlabel_frames:\n";
  for (const LabelRecord& label : series.labels)
    meta << "- " << Quoted(label.frame) << "\n";
  WriteFileAtomically((sequence / "meta.yml").string(), meta.str());
}

// The label seen from one camera: labels_%06d.npz's arrays.
NamedArrays CameraLabels(const LabelRecord& label, const RigCamera& camera,
                         const PcaPose& pca, const Eigen::VectorXd& betas10) {
  const Eigen::Matrix3d rotation = camera.cam_from_world.rotation.toRotationMatrix();
  const HandParams in_camera =
      ParamsInFrame(label, rotation, camera.cam_from_world.translation);
  double pose_m[51];
  Eigen::Map<Eigen::Vector3d>{pose_m} = in_camera.global_orient;
  Eigen::Map<Eigen::VectorXd>(pose_m + 3, kNumPoseParams) =
      pca.Coefficients(in_camera.hand_pose);
  Eigen::Map<Eigen::Vector3d>{pose_m + 48} = in_camera.transl;
  double joint_3d[3 * kNumHandKeypoints], joint_2d[2 * kNumHandKeypoints];
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector3d p =
        camera.cam_from_world * Eigen::Vector3d(label.mesh.keypoints.row(k).transpose());
    Eigen::Map<Eigen::Vector3d>{joint_3d + 3 * k} = p;
    Eigen::Vector2d uv(-1, -1);  // DexYCB's "no position"
    if (!camera.camera.Project(p, &uv)) uv.setConstant(-1);
    Eigen::Map<Eigen::Vector2d>{joint_2d + 2 * k} = uv;
  }
  return {
      {"pose_y", NdArray::FromDoublesAsFloat32({0, 3, 4}, nullptr)},
      {"pose_m", NdArray::FromDoublesAsFloat32({1, 51}, pose_m)},
      {"joint_3d", NdArray::FromDoublesAsFloat32({1, kNumHandKeypoints, 3}, joint_3d)},
      {"joint_2d", NdArray::FromDoublesAsFloat32({1, kNumHandKeypoints, 2}, joint_2d)},
      {"mano_betas", NdArray::FromDoublesAsFloat32({1, 10}, betas10.data())}};
}

Eigen::VectorXd Betas10(const HandParams& params) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(10);
  const int n = std::min<int>(10, static_cast<int>(params.betas.size()));
  out.head(n) = params.betas.head(n);
  return out;
}

}  // namespace

std::string WriteDexYcbLayout(const LabelSeries& series, const HandModel& model,
                              const SeriesCapture& capture,
                              const DatasetLayoutOptions& options) {
  RequireParameters(series, "dexycb");
  const PcaPose pca(model);
  const fs::path root(options.out);
  const Eigen::VectorXd betas = Betas10(*series.labels.front().params);
  WriteCalibration(root, capture.rig, betas);
  const fs::path sequence = root / kSubject / SeriesName(series);
  WriteMeta(sequence, series, capture.rig);
  int other_betas = 0;
  for (size_t f = 0; f < series.labels.size(); ++f) {
    const LabelRecord& label = series.labels[f];
    const Eigen::VectorXd frame_betas = Betas10(*label.params);
    other_betas += (frame_betas - betas).cwiseAbs().maxCoeff() > 0;
    for (size_t c = 0; c < capture.rig.size(); ++c) {
      const fs::path folder = sequence / capture.rig[c].name;
      const std::string number = ZeroPadded(static_cast<int64_t>(f), 6);
      PlaceImage(capture.images[f][c], (folder / ("color_" + number + ".jpg")).string(),
                 options.images);
      const std::string npz = (folder / ("labels_" + number + ".npz")).string();
      WriteNpzFile(npz, CameraLabels(label, capture.rig[c], pca, frame_betas));
    }
  }
  std::string what = "DexYCB sequence " + sequence.string() + ", " +
                     std::to_string(capture.rig.size()) + " cameras, images " +
                     (options.images == ImagePlacement::kLink ? "linked" : "copied");
  if (other_betas > 0) {
    what += "; " + std::to_string(other_betas) +
            (other_betas == 1 ? " label has" : " labels have") +
            " other betas than mano.yml's (frame " + series.labels.front().frame +
            "'s): their labels npz's mano_betas hold them";
  }
  return what;
}

}  // namespace handlabel
