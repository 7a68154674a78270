#pragma once
#include "core/core_versions.h"

namespace handlabel {
// LibTorch version and its intra-op thread count.
VersionList NetworkLibraryVersions();
}  // namespace handlabel
