#include "network/network_versions.h"

#include <torch/version.h>
#include <ATen/Parallel.h>

namespace handlabel {

VersionList NetworkLibraryVersions() {
  return {{"LibTorch", TORCH_VERSION},
          {"LibTorch threads", std::to_string(at::get_num_threads())}};
}

}  // namespace handlabel
