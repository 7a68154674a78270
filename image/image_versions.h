#pragma once
#include "core/core_versions.h"

namespace handlabel {
// zlib and libpng as linked into image.
VersionList ImageLibraryVersions();
}  // namespace handlabel
