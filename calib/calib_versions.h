#pragma once
#include "core/core_versions.h"

namespace handlabel {
// OpenCV and Ceres as linked into calib.
VersionList CalibLibraryVersions();
}  // namespace handlabel
