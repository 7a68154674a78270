#include "pipeline/hand_model_source.h"

#include <cstdlib>
#include <filesystem>

#include "core/errors.h"
#include "core/hand_model_io.h"
#include "pipeline/build_config.h"
#include "core/capsule_hand.h"

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
  // The file's own side (own format, or MANO_LEFT / MANO_RIGHT in the name) wins; a
  // file that records no side is taken as the side asked for.
  HandModelLoadOptions options;
  try {
    out.model = LoadHandModel(value, options);
  } catch (const InputError& e) {
    if (e.field() != "side") throw;
    options.side = side;
    out.model = LoadHandModel(value, options);
  }
  if (out.model.side != side) {
    const auto name = [](HandSide s) { return s == HandSide::kLeft ? "left" : "right"; };
    throw InputError(origin, "hand model", std::string("a ") + name(side) + " hand model",
                     value + " (a " + name(out.model.side) + " hand)");
  }
  out.source = value;
  return out;
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
