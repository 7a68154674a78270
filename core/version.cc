#include "core/version.h"

namespace handlabel {

std::string HandlabelVersion() { return HANDLABEL_VERSION; }

}  // namespace handlabel
