#pragma once
#include "core/core_versions.h"

namespace handlabel {
VersionList FittingLibraryVersions();
}  // namespace handlabel
