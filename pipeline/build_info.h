#pragma once
// What this binary is: version, git hash, build type and every dependency's version.
#include <string>

#include "core/core_versions.h"

namespace handlabel {

struct BuildInfo {
  std::string version;
  std::string git_hash;
  std::string build_type;
  VersionList dependencies;
};

BuildInfo GetBuildInfo();

}  // namespace handlabel
