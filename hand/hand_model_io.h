#pragma once
// Loading and saving hand models, none of it needing Python.
//
// LoadHandModel reads, detecting the format from the content:
//   kManoPickle     the official MANO_RIGHT.pkl / MANO_LEFT.pkl (Python 2 pickle with
//                   chumpy Ch / Select objects and a scipy csc_matrix J_regressor)
//   kPickle         re-saved MANO pickles (protocols 3-5, numpy._core names, no chumpy)
//   kSmplxNpz       .npz conversions with smplx-style keys (v_template, f, shapedirs,
//                   posedirs, J_regressor dense or as a pickled sparse object,
//                   weights, kintree_table, hands_components, hands_mean)
//   kHandlabelNpz   the project's own file: a smplx-style .npz (so numpy reads
//                   it too) plus handlabel_* entries; see docs/hand-model-files.md.
// Every loaded model has passed HandModel::Check. Errors are InputErrors naming the
// file and the key.

#include <array>
#include <optional>
#include <string>

#include "hand/hand_model.h"

namespace handlabel {

enum class HandModelFormat { kManoPickle, kPickle, kSmplxNpz, kHandlabelNpz };
const char* HandModelFormatName(HandModelFormat format);

// Own format version written by SaveHandModel (entry handlabel_version).
constexpr int kHandModelFileVersion = 1;

struct HandModelLoadOptions {
  // Side for files that do not record it (MANO pickles and smplx npz). Default: from
  // the file name ("left" / "right", any case, as in MANO_LEFT.pkl); if the name says
  // neither, loading fails and asks for it.
  std::optional<HandSide> side;
  // Fingertip vertex ids (thumb, index, middle, ring, pinky) for files without them.
  // Default: manopth's [745, 317, 444, 556, 673] for 778-vertex MANO models; other
  // vertex counts must pass them.
  std::optional<std::array<int, 5>> tip_vertex_ids;
};

struct LoadedHandModel {
  HandModel model;
  HandModelFormat format = HandModelFormat::kHandlabelNpz;
};

LoadedHandModel LoadHandModelFile(const std::string& path,
                                  const HandModelLoadOptions& options = {});
inline HandModel LoadHandModel(const std::string& path,
                               const HandModelLoadOptions& options = {}) {
  return LoadHandModelFile(path, options).model;
}

// Writes the own format (compressed .npz), atomically (temporary file + rename).
void SaveHandModel(const HandModel& model, const std::string& path);

}  // namespace handlabel
