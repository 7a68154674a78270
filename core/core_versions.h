#pragma once
// Versions of the libraries core is built against, for `handlabel version`.
#include <string>
#include <utility>
#include <vector>

namespace handlabel {
using VersionList = std::vector<std::pair<std::string, std::string>>;
VersionList CoreLibraryVersions();
}  // namespace handlabel
