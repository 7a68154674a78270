#include "pipeline/build_info.h"

#include <oneapi/tbb/version.h>
#include <yaml-cpp/yaml.h>

#include "calib/calib_versions.h"
#include "core/version.h"
#include "fitting/fitting_versions.h"
#include "image/image_versions.h"
#include "network/poem/network_versions.h"
#include "pipeline/build_config.h"
#include "pipeline/git_hash.h"

namespace handlabel {

BuildInfo GetBuildInfo() {
  BuildInfo info{HandlabelVersion(), HANDLABEL_GIT_HASH, HANDLABEL_BUILD_TYPE, {}};
  auto append = [&info](const VersionList& list) {
    for (const auto& entry : list) {
      bool seen = false;
      for (const auto& existing : info.dependencies)
        seen |= existing.first == entry.first;
      if (!seen) info.dependencies.push_back(entry);
    }
  };
  append(CoreLibraryVersions());
  append(ImageLibraryVersions());
  append(CalibLibraryVersions());
  append(FittingLibraryVersions());
  append(NetworkLibraryVersions());
  append({{"oneTBB", TBB_VERSION_STRING}});
  return info;
}

}  // namespace handlabel
