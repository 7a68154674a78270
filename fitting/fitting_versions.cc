#include "fitting/fitting_versions.h"

#include <ceres/version.h>

namespace handlabel {

VersionList FittingLibraryVersions() { return {{"Ceres", CERES_VERSION_STRING}}; }

}  // namespace handlabel
