#include "image/image_versions.h"

#include <png.h>
#include <zlib.h>

namespace handlabel {

VersionList ImageLibraryVersions() {
  return {
      {"zlib", zlibVersion()},
      {"libpng", png_get_libpng_ver(nullptr)},
  };
}

}  // namespace handlabel
