#include "pipeline/label_record.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/errors.h"
#include "core/atomic_file.h"

namespace handlabel {
namespace {

using nlohmann::json;

constexpr int kManoBetas = 10;

json Points(const Points3d& points) {
  json rows = json::array();
  for (int i = 0; i < points.rows(); ++i) {
    rows.push_back({points(i, 0), points(i, 1), points(i, 2)});
  }
  return rows;
}

json Vector(const Eigen::VectorXd& v) {
  json out = json::array();
  for (int i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

// JSON has no infinity or NaN; nlohmann writes them as null, read back as NaN.
double Number(const json& j) {
  return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>();
}

Points3d ReadPoints(const json& j, const std::string& source, const char* field,
                    int expected_rows) {
  if (!j.is_array() || (expected_rows >= 0 && int(j.size()) != expected_rows)) {
    throw InputError(source, field,
                     expected_rows >= 0
                         ? std::to_string(expected_rows) + " points [x, y, z]"
                         : "a list of points [x, y, z]");
  }
  Points3d points(j.size(), 3);
  for (size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_array() || j[i].size() != 3) {
      throw InputError(source, std::string(field) + "[" + std::to_string(i) + "]",
                       "[x, y, z]");
    }
    for (int c = 0; c < 3; ++c) points(i, c) = Number(j[i][c]);
  }
  return points;
}

Eigen::VectorXd ReadVector(const json& j, const std::string& source,
                           const std::string& field, int size) {
  if (!j.is_array() || (size >= 0 && int(j.size()) != size)) {
    throw InputError(source, field,
                     size >= 0 ? std::to_string(size) + " numbers" : "numbers");
  }
  Eigen::VectorXd v(j.size());
  for (size_t i = 0; i < j.size(); ++i) v[i] = Number(j[i]);
  return v;
}

std::string FormatCoordinate(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

}  // namespace

std::string ToString(LabelPath path) {
  switch (path) {
    case LabelPath::kNetwork:
      return "network";
    case LabelPath::kRefined:
      return "refined";
    case LabelPath::kFallbackFit:
      return "fallback_fit";
  }
  return "?";
}

LabelPath ParseLabelPath(const std::string& text, const std::string& source) {
  for (LabelPath p :
       {LabelPath::kNetwork, LabelPath::kRefined, LabelPath::kFallbackFit}) {
    if (text == ToString(p)) return p;
  }
  throw InputError(source, "path", "network | refined | fallback_fit", "'" + text + "'");
}

json LabelToJson(const LabelRecord& label) {
  json j;
  j["format"] = "handlabel-label";
  j["format_version"] = kLabelFormatVersion;
  j["frame"] = label.frame;
  j["hand_side"] = label.side == HandSide::kLeft ? "left" : "right";
  j["path"] = ToString(label.path);
  if (label.params) {
    Eigen::VectorXd betas =
        Eigen::VectorXd::Zero(std::max<int>(kManoBetas, label.params->betas.size()));
    betas.head(label.params->betas.size()) = label.params->betas;
    j["mano"] = {{"global_orient", Vector(label.params->global_orient)},
                 {"hand_pose", Vector(label.params->hand_pose)},
                 {"betas", Vector(betas)},
                 {"transl", Vector(label.params->transl)}};
  } else {
    j["mano"] = nullptr;
  }
  j["keypoints_order"] = "snap21";
  j["keypoints_3d"] = Points(label.mesh.keypoints);
  j["joints_native"] = Points(label.mesh.joints);
  j["vertices"] = Points(label.mesh.vertices);
  json checks = json::array();
  for (const QualityFlag& f : label.quality.flags) {
    checks.push_back({{"name", f.name},
                      {"passed", f.passed},
                      {"value", f.value},
                      {"threshold", f.threshold},
                      {"detail", f.detail}});
  }
  j["quality"] = {{"checked", !label.quality.flags.empty()},
                  {"passed", label.quality.Passed()},
                  {"checks", checks}};
  j["fit"] = label.fit;
  const Provenance& p = label.provenance;
  j["provenance"] = {{"network_model", p.network_model},
                     {"weights_sha256", p.weights_sha256},
                     {"hand_model", p.hand_model},
                     {"job_hash", p.job_hash},
                     {"version", p.version},
                     {"git_hash", p.git_hash},
                     {"seed", p.seed}};
  return j;
}

LabelRecord LabelFromJson(const json& j, const std::string& source) {
  if (!j.is_object() || j.value("format", "") != "handlabel-label") {
    throw InputError(source, "format", "'handlabel-label'");
  }
  if (j.value("format_version", 0) != kLabelFormatVersion) {
    throw InputError(source, "format_version", std::to_string(kLabelFormatVersion));
  }
  LabelRecord label;
  try {
    label.frame = j.at("frame").get<std::string>();
    label.side = j.at("hand_side").get<std::string>() == "left" ? HandSide::kLeft
                                                                : HandSide::kRight;
    label.path = ParseLabelPath(j.at("path").get<std::string>(), source);
    const json& mano = j.at("mano");
    if (!mano.is_null()) {
      HandParams params;
      params.global_orient =
          ReadVector(mano.at("global_orient"), source, "mano.global_orient", 3);
      params.hand_pose =
          ReadVector(mano.at("hand_pose"), source, "mano.hand_pose", kNumPoseParams);
      params.betas = ReadVector(mano.at("betas"), source, "mano.betas", -1);
      params.transl = ReadVector(mano.at("transl"), source, "mano.transl", 3);
      label.params = params;
    }
    label.mesh.keypoints =
        ReadPoints(j.at("keypoints_3d"), source, "keypoints_3d", kNumHandKeypoints);
    label.mesh.joints =
        ReadPoints(j.at("joints_native"), source, "joints_native", kNumHandJoints);
    label.mesh.vertices = ReadPoints(j.at("vertices"), source, "vertices", -1);
    for (const json& c : j.at("quality").at("checks")) {
      label.quality.flags.push_back({c.at("name").get<std::string>(),
                                     c.at("passed").get<bool>(), Number(c.at("value")),
                                     Number(c.at("threshold")),
                                     c.at("detail").get<std::string>()});
    }
    label.fit = j.at("fit");
    const json& p = j.at("provenance");
    label.provenance = {p.at("network_model").get<std::string>(),
                        p.at("weights_sha256").get<std::string>(),
                        p.at("hand_model").get<std::string>(),
                        p.at("job_hash").get<std::string>(),
                        p.at("version").get<std::string>(),
                        p.at("git_hash").get<std::string>(),
                        p.at("seed").get<uint64_t>()};
  } catch (const json::exception& e) {
    throw InputError(source, "label", "a complete handlabel label", e.what());
  }
  return label;
}

LabelRecord ReadLabelFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "a readable label file", "cannot open it");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path, "", "valid JSON", e.what());
  }
  return LabelFromJson(j, path);
}

std::string FrameFileStem(const std::string& frame, const std::string& source) {
  if (frame.empty() || frame.front() == '.' || frame.front() == '/') {
    throw InputError(source, "frame id", "a non-empty id not starting with '.' or '/'",
                     "'" + frame + "'");
  }
  std::string stem;
  for (char c : frame) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                       (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
    if (c == '/') {
      stem += "__";
    } else if (plain) {
      stem += c;
    } else {
      throw InputError(source, "frame id", "letters, digits, '.', '_', '-' or '/'",
                       "'" + frame + "'");
    }
  }
  return stem;
}

std::string LabelFilePath(const std::string& output_dir, const std::string& frame) {
  return output_dir + "/labels/" + FrameFileStem(frame, "frame id") + ".json";
}

std::string MeshFilePath(const std::string& output_dir, const std::string& frame,
                         const std::string& extension) {
  return output_dir + "/meshes/" + FrameFileStem(frame, "frame id") + "." + extension;
}

std::string MeshToPly(const Points3d& vertices, const Faces& faces) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment handlabel hand mesh, metres\n"
      << "element vertex " << vertices.rows() << "\nproperty float x\nproperty float y\n"
      << "property float z\nelement face " << faces.rows()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < vertices.rows(); ++i) {
    out << FormatCoordinate(vertices(i, 0)) << " " << FormatCoordinate(vertices(i, 1))
        << " " << FormatCoordinate(vertices(i, 2)) << "\n";
  }
  for (int f = 0; f < faces.rows(); ++f) {
    out << "3 " << faces(f, 0) << " " << faces(f, 1) << " " << faces(f, 2) << "\n";
  }
  return out.str();
}

std::string MeshToObj(const Points3d& vertices, const Faces& faces) {
  std::ostringstream out;
  out << "# handlabel hand mesh, metres\n";
  for (int i = 0; i < vertices.rows(); ++i) {
    out << "v " << FormatCoordinate(vertices(i, 0)) << " "
        << FormatCoordinate(vertices(i, 1)) << " " << FormatCoordinate(vertices(i, 2))
        << "\n";
  }
  for (int f = 0; f < faces.rows(); ++f) {
    out << "f " << faces(f, 0) + 1 << " " << faces(f, 1) + 1 << " " << faces(f, 2) + 1
        << "\n";
  }
  return out.str();
}

void WriteLabelFiles(const std::string& output_dir, const LabelRecord& label,
                     const Faces& faces, const std::vector<std::string>& mesh_formats) {
  for (const std::string& format : mesh_formats) {
    const std::string text = format == "obj" ? MeshToObj(label.mesh.vertices, faces)
                                             : MeshToPly(label.mesh.vertices, faces);
    WriteFileAtomically(MeshFilePath(output_dir, label.frame, format), text);
  }
  WriteFileAtomically(LabelFilePath(output_dir, label.frame),
                      LabelToJson(label).dump(1) + "\n");
}

}  // namespace handlabel
