#include "core/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace handlabel {

std::string DataDir() {
  if (const char* env = std::getenv("HANDLABEL_DATA_DIR"); env && *env) return env;
  // /proc/self/exe names the executable with symlinks resolved, so a link to an
  // installed binary (e.g. from /usr/local/bin) still finds the install's data.
  std::error_code error;
  const std::filesystem::path exe =
      std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "";
  return (exe.parent_path() / ".." / "share" / "handlabel").lexically_normal().string();
}

std::string ShippedModelPath(const std::string& name) {
  const std::string dir = DataDir();
  if (dir.empty()) return "";
  return (std::filesystem::path(dir) / "models" / name).string();
}

}  // namespace handlabel
