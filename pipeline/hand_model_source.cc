#include "pipeline/hand_model_source.h"

#include <cstdlib>
#include <filesystem>

#include "core/data_dir.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_model_io.h"
#include "openhand/builder.h"

namespace handlabel {
namespace {

// A file given by flag, field or variable, checked against the side asked for.
ResolvedHandModel FromFile(const std::string& path, std::optional<HandSide> side,
                           const HandModelOrigin& origin) {
  if (!std::filesystem::exists(path)) {
    throw InputError(origin.source, origin.field, "an existing model file or \"capsule\"",
                     path);
  }
  // The file's own side (own format, or MANO_LEFT / MANO_RIGHT in the name) wins; a
  // file that records no side is taken as the side asked for.
  ResolvedHandModel out;
  HandModelLoadOptions options;
  try {
    out.model = LoadHandModel(path, options);
  } catch (const InputError& e) {
    if (e.field() != "side" || !side) throw;
    options.side = side;
    out.model = LoadHandModel(path, options);
  }
  if (side && out.model.side != *side) {
    throw InputError(origin.source, origin.field,
                     "a " + HandSideName(*side) + " hand model",
                     path + " (a " + HandSideName(out.model.side) + " hand)");
  }
  out.source = path;
  return out;
}

ResolvedHandModel FromValue(const std::string& value, std::optional<HandSide> side,
                            const HandModelOrigin& origin) {
  if (value != "capsule") return FromFile(value, side, origin);
  ResolvedHandModel out;
  out.model = MakeCapsuleHand(side.value_or(HandSide::kRight));
  out.source = "builtin:capsule";
  return out;
}

// The documented fallback when no data folder holds the shipped file.
ResolvedHandModel BuildDefaultOpenHand(HandSide side, const std::string& shipped) {
  OpenHandBuildOptions options;
  options.side = side;
  ResolvedHandModel out;
  out.model = BuildOpenHand(DefaultOpenHandDesign(), options);
  out.source = "builtin:open_hand_" + HandSideName(side) + " (built in memory)";
  out.note = "no hand model file given and " +
             (shipped.empty() ? "no data folder" : shipped) +
             " not found (set HANDLABEL_DATA_DIR): built the open hand in memory";
  return out;
}

}  // namespace

ResolvedHandModel ResolveHandModel(const std::string& value, std::optional<HandSide> side,
                                   const HandModelOrigin& origin) {
  if (!value.empty()) return FromValue(value, side, origin);
  if (const char* env = std::getenv("HANDLABEL_HAND_MODEL"); env && *env) {
    return FromValue(env, side, {"HANDLABEL_HAND_MODEL", "hand model"});
  }
  const HandSide shipped_side = side.value_or(HandSide::kRight);
  const std::string shipped =
      ShippedModelPath("open_hand_" + HandSideName(shipped_side) + ".npz");
  if (!shipped.empty() && std::filesystem::exists(shipped)) {
    return FromFile(shipped, shipped_side, {shipped, "hand model"});
  }
  return BuildDefaultOpenHand(shipped_side, shipped);
}

}  // namespace handlabel
