#include "network/poem/network_versions.h"

#include <ATen/Parallel.h>
#include <torch/version.h>

namespace handlabel {

VersionList NetworkLibraryVersions() {
  return {{"LibTorch", TORCH_VERSION},
          {"LibTorch threads", std::to_string(at::get_num_threads())}};
}

}  // namespace handlabel
