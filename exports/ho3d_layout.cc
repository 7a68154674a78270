#include "exports/ho3d_layout.h"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "formats/pickle_writer.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

constexpr char kSequence[] = "HANDLABEL";  // camera folders HANDLABEL0, HANDLABEL1, ...
constexpr int kWidth = 640, kHeight = 480;

std::string Number(double v) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

// OpenCV camera axes -> HO3D's OpenGL axes (y up, z backwards): diag(1, -1, -1).
const Eigen::Matrix3d kGlFromCv = Eigen::Vector3d(1, -1, -1).asDiagonal();

void WriteCalibration(const fs::path& dir, const Rig& rig) {
  std::string orders;
  for (size_t i = 0; i < rig.size(); ++i) {
    const RigCamera& camera = rig[i];
    if (camera.camera.width() != kWidth || camera.camera.height() != kHeight) {
      throw InputError("camera " + camera.name, "size",
                       "640 x 480 (HO3D's calibration files carry no image size; its "
                       "tools and our reader assume 640 x 480)",
                       std::to_string(camera.camera.width()) + " x " +
                           std::to_string(camera.camera.height()));
    }
    const Eigen::Vector4d k = PinholeIntrinsics(camera, "HO3D");
    const std::string index = std::to_string(i);
    orders += (i ? " " : "") + index;
    WriteFileAtomically((dir / ("cam_" + index + "_intrinsics.txt")).string(),
                        "fx:" + Number(k[0]) + ", fy:" + Number(k[1]) +
                            ", ppx:" + Number(k[2]) + ", ppy:" + Number(k[3]) + "\n");
    const Matrix3x4d m = camera.cam_from_world.Inverse().ToMatrix();  // camera -> world
    std::string trans;
    for (int r = 0; r < 3; ++r) {
      trans += Number(m(r, 0)) + " " + Number(m(r, 1)) + " " + Number(m(r, 2)) + " " +
               Number(m(r, 3)) + "\n";
    }
    WriteFileAtomically((dir / ("trans_" + index + ".txt")).string(),
                        trans + "0 0 0 1\n");
  }
  WriteFileAtomically((dir / "cam_orders.txt").string(), orders + "\n");
}

// One camera's meta pickle of one label.
std::string MetaPickle(const LabelRecord& label, const RigCamera& camera) {
  const Eigen::Matrix3d gl_from_world =
      kGlFromCv * camera.cam_from_world.rotation.toRotationMatrix();
  const HandParams in_gl =
      ParamsInFrame(label, gl_from_world, kGlFromCv * camera.cam_from_world.translation);
  double pose[48], trans[3], betas[10] = {0}, joints[3 * kNumHandKeypoints];
  Eigen::Map<Eigen::Vector3d>{pose} = in_gl.global_orient;
  Eigen::Map<Eigen::VectorXd>(pose + 3, kNumPoseParams) = in_gl.hand_pose;
  Eigen::Map<Eigen::Vector3d>{trans} = in_gl.transl;
  for (int b = 0; b < std::min<int>(10, static_cast<int>(in_gl.betas.size())); ++b)
    betas[b] = in_gl.betas[b];
  for (int k = 0; k < kNumHandKeypoints; ++k) {  // SNAP -> MANO order + tips
    Eigen::Map<Eigen::Vector3d>{joints + 3 * kSnapFromNative[k]} =
        kGlFromCv * (camera.cam_from_world *
                     Eigen::Vector3d(label.mesh.keypoints.row(k).transpose()));
  }
  const Eigen::Vector4d k = PinholeIntrinsics(camera, "HO3D");
  const double cam_mat[9] = {k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1};
  return PickleArrayDict(
      {{"handPose", NdArray::FromDoublesAsFloat32({48}, pose)},
       {"handTrans", NdArray::FromDoublesAsFloat32({3}, trans)},
       {"handBeta", NdArray::FromDoublesAsFloat32({10}, betas)},
       {"handJoints3D", NdArray::FromDoublesAsFloat32({kNumHandKeypoints, 3}, joints)},
       {"camMat", NdArray::FromDoublesAsFloat32({3, 3}, cam_mat)}});
}

// .jpg or .png as the capture's file is named (HO3D's reader takes either).
std::string ImageExtension(const std::string& image) {
  const std::string extension = fs::path(image).extension().string();
  if (extension == ".png" || extension == ".PNG") return ".png";
  return ".jpg";
}

}  // namespace

std::string WriteHo3dLayout(const LabelSeries& series, const SeriesCapture& capture,
                            const DatasetLayoutOptions& options) {
  RequireParameters(series, "ho3d");
  if (series.side != HandSide::kRight) {
    throw InputError(series.FileOf(series.labels.front().frame), "hand_side",
                     "right (HO3D shows right hands; its tools load MANO_RIGHT)",
                     HandSideName(series.side));
  }
  const fs::path root(options.out);
  const fs::path calibration = root / "calibration" / kSequence;
  WriteCalibration(calibration / "calibration", capture.rig);
  nlohmann::json index = {{"labels", series.labels_dir},
                          {"frames", nlohmann::json::array()},
                          {"cameras", nlohmann::json::array()}};
  for (const RigCamera& camera : capture.rig.cameras())
    index["cameras"].push_back(camera.name);
  for (size_t f = 0; f < series.labels.size(); ++f) {
    const LabelRecord& label = series.labels[f];
    const std::string fid = ZeroPadded(static_cast<int64_t>(f), 4);
    index["frames"].push_back({{"fid", fid}, {"frame", label.frame}});
    for (size_t c = 0; c < capture.rig.size(); ++c) {
      const fs::path folder = root / "train" / (kSequence + std::to_string(c));
      const std::string& image = capture.images[f][c];
      PlaceImage(image, (folder / "rgb" / (fid + ImageExtension(image))).string(),
                 options.images);
      WriteFileAtomically((folder / "meta" / (fid + ".pkl")).string(),
                          MetaPickle(label, capture.rig[c]));
    }
  }
  WriteFileAtomically((calibration / "handlabel.json").string(), index.dump(1) + "\n");
  return "HO3D sequence " + (root / "train" / kSequence).string() + " (" +
         std::to_string(capture.rig.size()) + " camera folders " + kSequence +
         "<i>), images " +
         (options.images == ImagePlacement::kLink ? "linked" : "copied");
}

}  // namespace handlabel
