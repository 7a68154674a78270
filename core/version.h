#pragma once
// The handlabel version (CMake's project version), for provenance records written by
// any layer. The git hash and dependency versions are in pipeline/build_info.h.

#include <string>

namespace handlabel {

std::string HandlabelVersion();

}  // namespace handlabel
