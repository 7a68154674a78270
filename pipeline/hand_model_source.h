#pragma once
// Which hand model a command uses, in this order:
//   1. the --hand-model flag: a model file (MANO pickle, .npz) or "capsule"
//   2. the environment variable HANDLABEL_HAND_MODEL (same values)
//   3. the shipped open hand <source>/models/open_hand_<side>.npz
//   4. the built-in capsule hand (core/capsule_hand.h), with a note saying so
// The left hand is the mirror of the right for the built-ins.

#include <string>

#include "core/hand_model.h"

namespace handlabel {

struct ResolvedHandModel {
  HandModel model;
  std::string source;  // file path, or "builtin:capsule"
  std::string note;    // e.g. why the built-in is used; "" if nothing to say
};

// `flag` = the --hand-model value ("" if not given). Throws InputError naming the flag
// or variable when a given file cannot be loaded.
ResolvedHandModel ResolveHandModel(const std::string& flag, HandSide side);

}  // namespace handlabel
