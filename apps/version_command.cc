#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "pipeline/build_info.h"

namespace handlabel {

int RunVersion(int argc, char** argv) {
  CLI::App app("Print the handlabel version, git hash and dependency versions.",
               "version");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("version", [] {
    const BuildInfo info = GetBuildInfo();
    std::cout << "handlabel " << info.version << " (git " << info.git_hash << ", "
              << info.build_type << ")\n";
    for (const auto& [name, version] : info.dependencies) {
      std::cout << "  " << name << " " << version << "\n";
    }
    return 0;
  });
}

}  // namespace handlabel
