#include "pipeline/hand_model_source.h"

#include <cstdlib>
#include <filesystem>

#include "core/errors.h"
#include "pipeline/build_config.h"
#include "pipeline/capsule_hand.h"

namespace handlabel {
namespace {

ResolvedHandModel FromValue(const std::string& value, const std::string& origin,
                            HandSide side) {
  ResolvedHandModel out;
  if (value == "capsule") {
    out.model = MakeCapsuleHand(side);
    out.source = "builtin:capsule";
    return out;
  }
  if (!std::filesystem::exists(value)) {
    throw InputError(origin, "hand model", "an existing model file or \"capsule\"",
                     value);
  }
  // Model files load through core/hand_model_io.h (branch "loaders"), merged later.
  throw InputError(origin, "hand model",
                   "\"capsule\" (loading model files arrives with core/hand_model_io)",
                   value);
}

}  // namespace

ResolvedHandModel ResolveHandModel(const std::string& flag, HandSide side) {
  if (!flag.empty()) return FromValue(flag, "--hand-model", side);
  if (const char* env = std::getenv("HANDLABEL_HAND_MODEL"); env && *env) {
    return FromValue(env, "HANDLABEL_HAND_MODEL", side);
  }
  const std::string shipped = std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_" +
                              (side == HandSide::kLeft ? "left" : "right") + ".npz";
  if (std::filesystem::exists(shipped)) return FromValue(shipped, shipped, side);
  ResolvedHandModel out = FromValue("capsule", "", side);
  out.note = "no hand model file given and " + shipped +
             " not found: using the built-in capsule hand";
  return out;
}

}  // namespace handlabel
