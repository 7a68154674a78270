#include "core/core_versions.h"

#include <Eigen/Core>

#include <nlohmann/json.hpp>
#include "core/blas_library.h"

namespace handlabel {

VersionList CoreLibraryVersions() {
  const BlasLibrary blas = LoadedBlasLibrary();
  return {
      {"BLAS", blas.threading.empty() ? blas.name
                                      : blas.name + " (" + blas.threading + " build)"},
      {"Eigen", std::to_string(EIGEN_WORLD_VERSION) + "." +
                    std::to_string(EIGEN_MAJOR_VERSION) + "." +
                    std::to_string(EIGEN_MINOR_VERSION)},
      {"nlohmann_json", std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." +
                            std::to_string(NLOHMANN_JSON_VERSION_MINOR) + "." +
                            std::to_string(NLOHMANN_JSON_VERSION_PATCH)},
  };
}

}  // namespace handlabel
