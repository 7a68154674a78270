#include "pipeline/label_record.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/json_util.h"
#include "hand/hand_params_json.h"

namespace handlabel {
namespace {

using nlohmann::json;

constexpr int kManoBetas = 10;

// Quality values may be NaN or infinite (nlohmann writes null): null reads as NaN.
double Number(const json& j, const std::string& source, const std::string& field) {
  return JsonNumber(j, source, field, JsonNull::kAsNan);
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
  j["hand_side"] = HandSideName(label.side);
  j["path"] = ToString(label.path);
  if (label.params) {
    Eigen::VectorXd betas =
        Eigen::VectorXd::Zero(std::max<int>(kManoBetas, label.params->betas.size()));
    betas.head(label.params->betas.size()) = label.params->betas;
    HandParams padded = *label.params;  // MANO's 10 betas at least
    padded.betas = betas;
    j["mano"] = JsonHandParams(padded);
  } else {
    j["mano"] = nullptr;
  }
  j["keypoints_order"] = "snap21";
  j["keypoints_3d"] = JsonPoints(label.mesh.keypoints);
  j["joints_native"] = JsonPoints(label.mesh.joints);
  j["vertices"] = JsonPoints(label.mesh.vertices);
  json checks = json::array();
  for (const QualityFlag& f : label.quality.flags) checks.push_back(QualityFlagJson(f));
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
    label.side = ParseHandSide(j.at("hand_side").get<std::string>(), source, "hand_side");
    label.path = ParseLabelPath(j.at("path").get<std::string>(), source);
    const json& mano = j.at("mano");
    if (!mano.is_null()) {
      label.params = HandParamsFromJson(mano, source, "mano.", JsonNull::kAsNan);
    }
    // The point lists are what label consumers use: a missing one is named.
    label.mesh.keypoints =
        JsonPointList(JsonMember(j, "keypoints_3d", source), source, "keypoints_3d",
                      kNumHandKeypoints, JsonNull::kAsNan);
    label.mesh.joints = JsonPointList(JsonMember(j, "joints_native", source), source,
                                      "joints_native", kNumHandJoints, JsonNull::kAsNan);
    label.mesh.vertices = JsonPointList(JsonMember(j, "vertices", source), source,
                                        "vertices", -1, JsonNull::kAsNan);
    for (const json& c : j.at("quality").at("checks")) {
      label.quality.flags.push_back(
          {c.at("name").get<std::string>(), c.at("passed").get<bool>(),
           Number(c.at("value"), source, "quality.value"),
           Number(c.at("threshold"), source, "quality.threshold"),
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
