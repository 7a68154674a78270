// The looks' names, apart from the renderer so that config readers (and their fuzz
// targets) need not link it.
#include "capture/synth_appearance.h"
#include "core/errors.h"

namespace handlabel {

SynthAppearance SynthAppearanceFromName(const std::string& name,
                                        const std::string& source,
                                        const std::string& field) {
  if (name == "basic") return SynthAppearance::kBasic;
  if (name == "realistic") return SynthAppearance::kRealistic;
  throw InputError(source, field, "basic | realistic", "'" + name + "'");
}

std::string SynthAppearanceName(SynthAppearance appearance) {
  return appearance == SynthAppearance::kRealistic ? "realistic" : "basic";
}

}  // namespace handlabel
