#include "calib/calib_versions.h"

#include <ceres/version.h>

#include <opencv2/core/version.hpp>

namespace handlabel {

VersionList CalibLibraryVersions() {
  return {{"OpenCV", CV_VERSION}, {"Ceres", CERES_VERSION_STRING}};
}

}  // namespace handlabel
