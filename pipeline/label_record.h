#pragma once
// One frame's label as written by a labeling job: MANO-compatible parameters,
// vertices, joints in both orders, the quality checks of the network's answer, which
// path produced it and where it came from. Written atomically as
// <output.dir>/labels/<frame>.json (format in docs/labeling-jobs.md), optionally with
// meshes/<frame>.ply|.obj. Labels hold nothing run-dependent (no timings, no host), so
// the same job on the same inputs writes byte-identical files however it is sharded.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/point_arrays.h"
#include "hand/hand_lbs.h"
#include "pipeline/quality_checks.h"

namespace handlabel {

// Which stage produced the label.
enum class LabelPath {
  kNetwork,      // the network's mesh, accepted by the quality checks (or refine off)
  kRefined,      // the network's mesh refined by the fitter (refine always)
  kFallbackFit,  // fitted from 2D evidence alone (no network, or its answer failed QA)
};
std::string ToString(LabelPath path);
// Throws InputError naming `source` for an unknown name.
LabelPath ParseLabelPath(const std::string& text, const std::string& source);

struct Provenance {
  std::string network_model;   // "" when no network ran
  std::string weights_sha256;  // SHA-256 of the weights file, "" without network
  std::string hand_model;      // the hand model's name
  std::string job_hash;        // JobHash() of the job (label_job.h)
  std::string version;         // handlabel version
  std::string git_hash;        // of the handlabel build
  uint64_t seed = 0;           // the job's seed
};

struct LabelRecord {
  std::string frame;
  HandSide side = HandSide::kRight;
  LabelPath path = LabelPath::kNetwork;
  // MANO-compatible parameters (betas padded to 10); absent when the label is the
  // network's mesh alone and the network does not regress parameters.
  std::optional<HandParams> params;
  HandMesh mesh;          // vertices, 16 native joints, 21 SNAP keypoints
  QualityReport quality;  // checks of the network's answer; no flags if no network ran
  nlohmann::json fit;     // the fitter's report, null when no fit ran
  Provenance provenance;
};

constexpr int kLabelFormatVersion = 1;

nlohmann::json LabelToJson(const LabelRecord& label);
// Throws InputError naming `source` and the field when the JSON is not a label.
LabelRecord LabelFromJson(const nlohmann::json& json, const std::string& source);
LabelRecord ReadLabelFile(const std::string& path);

// Frame ids become file names: letters, digits, '.', '_', '-' and '/' (which becomes
// "__"); throws InputError naming `source` otherwise.
std::string FrameFileStem(const std::string& frame, const std::string& source);

// <output_dir>/labels/<stem>.json and friends.
std::string LabelFilePath(const std::string& output_dir, const std::string& frame);
std::string MeshFilePath(const std::string& output_dir, const std::string& frame,
                         const std::string& extension);  // "ply" | "obj"

// ASCII PLY / Wavefront OBJ text of a triangle mesh (vertices in metres).
std::string MeshToPly(const Points3d& vertices, const Faces& faces);
std::string MeshToObj(const Points3d& vertices, const Faces& faces);

// Writes the label JSON and, for each of `mesh_formats` ("ply", "obj"), the mesh, each
// atomically (temporary file + rename). The label JSON is written last, so a label on
// disk implies its meshes are complete.
void WriteLabelFiles(const std::string& output_dir, const LabelRecord& label,
                     const Faces& faces, const std::vector<std::string>& mesh_formats);

}  // namespace handlabel
