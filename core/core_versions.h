#pragma once
// Versions of the libraries core is built against, for `handlabel version`; each layer
// that links a library of its own lists it beside (image_versions.h, ...).
#include <string>
#include <utility>
#include <vector>

namespace handlabel {
using VersionList = std::vector<std::pair<std::string, std::string>>;
VersionList CoreLibraryVersions();
}  // namespace handlabel
