#pragma once
// Which hand model a command, label job or training run uses: the one place that
// decides, in this order (docs/hand-model-files.md):
//   1. the given value: the --hand-model flag or a job's / training config's
//      hand_model field: a model file (MANO pickle, .npz) or "capsule" (the built-in
//      capsule hand, hand/capsule_hand.h)
//   2. the environment variable HANDLABEL_HAND_MODEL (same values)
//   3. the shipped open hand <data dir>/models/open_hand_<side>.npz (core/data_dir.h)
//   4. the open hand built in memory from its default design and options (what the
//      shipped file holds; about 6 s), with a note saying so
// The left hand is the mirror of the right for the shipped and built-in models.

#include <optional>
#include <string>

#include "hand/hand_model.h"

namespace handlabel {

struct ResolvedHandModel {
  HandModel model;
  std::string source;  // file path, "builtin:capsule" or "builtin:open_hand_<side> ..."
  std::string note;    // e.g. why the built-in is used; "" if nothing to say
};

// Where a given value came from, named in errors.
struct HandModelOrigin {
  std::string source = "--hand-model";  // the flag, or the job / config file
  std::string field = "hand model";     // e.g. "hand_model" for a file's field
};

// `value` = the flag or field ("" if not given). `side` = the side asked for: a model
// of the other side is an error; std::nullopt takes a file's own side (right for the
// shipped and built-in models). Throws InputError naming the origin (or the variable)
// when a given file cannot be loaded.
ResolvedHandModel ResolveHandModel(const std::string& value, std::optional<HandSide> side,
                                   const HandModelOrigin& origin = {});

}  // namespace handlabel
