#include "calib/dataset_calib.h"

#include "core/errors.h"

namespace handlabel {

std::vector<std::string> DatasetRigFormats() { return {}; }

Rig ReadDatasetRig(const std::string& format, const std::string& path,
                   RigFileInfo* info) {
  throw InputError(path, "FORMAT", "a dataset format", "'" + format + "'");
}

}  // namespace handlabel
