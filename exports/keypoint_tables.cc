#include "exports/keypoint_tables.h"

#include <algorithm>
#include <limits>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "formats/npz.h"
#include "hand/hand_skeleton.h"

namespace handlabel {
namespace {

constexpr int kManoBetas = 10;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// (N, rows, 3) from one point list per label.
template <typename Points>
NdArray StackPoints(const LabelSeries& series, Points points_of) {
  const int64_t n = static_cast<int64_t>(series.labels.size());
  const int64_t rows = points_of(series.labels.front()).rows();
  std::vector<double> values;
  values.reserve(static_cast<size_t>(n * rows * 3));
  for (const LabelRecord& label : series.labels) {
    const Points3d& p = points_of(label);
    if (p.rows() != rows) {
      throw InputError(series.FileOf(label.frame), "points",
                       std::to_string(rows) + " rows as the first label",
                       std::to_string(p.rows()));
    }
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < 3; ++c) values.push_back(p(r, c));
  }
  return NdArray::FromDoubles({n, rows, 3}, values.data());
}

// The parameter arrays in the layer's convention; NaN rows for labels without them.
void AddParameters(const LabelSeries& series, const ManoLayerSetting& setting,
                   const HandModel* model, NamedArrays* arrays) {
  const int64_t n = static_cast<int64_t>(series.labels.size());
  Eigen::MatrixXd orient = Eigen::MatrixXd::Constant(n, 3, kNaN);
  Eigen::MatrixXd pose = Eigen::MatrixXd::Constant(n, kNumPoseParams, kNaN);
  Eigen::MatrixXd betas = Eigen::MatrixXd::Constant(n, kManoBetas, kNaN);
  Eigen::MatrixXd transl = Eigen::MatrixXd::Constant(n, 3, kNaN);
  std::vector<int64_t> has(n, 0);
  for (int64_t i = 0; i < n; ++i) {
    const std::optional<HandParams>& p = series.labels[i].params;
    if (!p) continue;
    if (!setting.flat_hand_mean && !model) {
      throw InputError("export", "hand model",
                       "the labels' hand model (flat_hand_mean false subtracts its "
                       "hands_mean)",
                       "none");
    }
    has[i] = 1;
    orient.row(i) = p->global_orient.transpose();
    pose.row(i) = setting.flat_hand_mean
                      ? Eigen::RowVectorXd(p->hand_pose.transpose())
                      : Eigen::RowVectorXd(LayerHandPose(*p, *model, false).transpose());
    betas.row(i).setZero();
    betas.row(i).head(std::min<Eigen::Index>(kManoBetas, p->betas.size())) =
        p->betas.head(std::min<Eigen::Index>(kManoBetas, p->betas.size())).transpose();
    transl.row(i) = p->transl.transpose();
  }
  arrays->emplace_back("has_mano", NdArray::FromInt64s({n}, has.data(), DType::kBool));
  arrays->emplace_back("global_orient", NdArray::FromMatrix(orient));
  arrays->emplace_back("hand_pose", NdArray::FromMatrix(pose));
  arrays->emplace_back("betas", NdArray::FromMatrix(betas));
  arrays->emplace_back("transl", NdArray::FromMatrix(transl));
  // manopth's and manotorch's layers take root and finger rotations as one vector.
  if (setting.convention != ManoConvention::kSmplx) {
    Eigen::MatrixXd coeffs(n, 3 + kNumPoseParams);
    coeffs << orient, pose;
    arrays->emplace_back("pose_coeffs", NdArray::FromMatrix(coeffs));
  }
}

}  // namespace

void WriteKeypointsNpz(const LabelSeries& series, const ManoLayerSetting& setting,
                       const HandModel* model, const std::string& path) {
  HL_CHECK(!series.labels.empty(), "a series has labels");
  std::vector<std::string> frames, paths;
  for (const LabelRecord& label : series.labels) {
    frames.push_back(label.frame);
    paths.push_back(ToString(label.path));
  }
  NamedArrays arrays;
  arrays.emplace_back("frames", NdArray::FromTexts(frames));
  arrays.emplace_back("label_path", NdArray::FromTexts(paths));
  arrays.emplace_back("keypoints_3d", StackPoints(series, [](const LabelRecord& l) {
                        return l.mesh.keypoints;
                      }));
  arrays.emplace_back("joints_native", StackPoints(series, [](const LabelRecord& l) {
                        return l.mesh.joints;
                      }));
  arrays.emplace_back("vertices", StackPoints(series, [](const LabelRecord& l) {
                        return l.mesh.vertices;
                      }));
  AddParameters(series, setting, model, &arrays);
  const int64_t flat = setting.flat_hand_mean ? 1 : 0;
  arrays.emplace_back("mano_convention", NdArray::FromText(ToString(setting.convention)));
  arrays.emplace_back("flat_hand_mean", NdArray::FromInt64s({}, &flat, DType::kBool));
  arrays.emplace_back("hand_side", NdArray::FromText(HandSideName(series.side)));
  arrays.emplace_back("hand_model", NdArray::FromText(series.hand_model));
  arrays.emplace_back("keypoints_order", NdArray::FromText("snap21"));
  arrays.emplace_back("units", NdArray::FromText("m"));
  WriteNpzFile(path, arrays, ZipMethod::kDeflate);  // atomic: never a half-written file
}

void WriteKeypointsCsv(const LabelSeries& series, const std::string& path) {
  std::ostringstream out;
  out.precision(17);  // round-trips every double
  out << "frame,path";
  for (const char* name : kSnapKeypointNames) {
    for (const char* axis : {"x", "y", "z"}) out << "," << name << "_" << axis;
  }
  out << "\n";
  for (const LabelRecord& label : series.labels) {
    // Frame ids are letters, digits, '.', '_', '-' and '/' (label_record.h): no quoting.
    out << label.frame << "," << ToString(label.path);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      for (int c = 0; c < 3; ++c) out << "," << label.mesh.keypoints(k, c);
    }
    out << "\n";
  }
  WriteFileAtomically(path, out.str());
}

}  // namespace handlabel
