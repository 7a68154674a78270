#include "core/blas_library.h"

#include <dlfcn.h>

namespace handlabel {
namespace {

// OpenBLAS's own entry points, looked up at run time: the program does not link BLAS
// itself, and another BLAS behind libblas.so.3 has none of them.
template <typename Function>
Function* OpenBlasFunction(const char* name) {
  return reinterpret_cast<Function*>(dlsym(RTLD_DEFAULT, name));
}

}  // namespace

BlasLibrary LoadedBlasLibrary() {
  const auto config = OpenBlasFunction<char*()>("openblas_get_config");
  const auto parallel = OpenBlasFunction<int()>("openblas_get_parallel");
  if (!config || !parallel) return {"unknown (not OpenBLAS)", ""};
  static const char* const kThreading[] = {"serial", "pthreads", "openmp"};
  const int mode = parallel();
  return {config(), mode >= 0 && mode <= 2 ? kThreading[mode] : "unknown"};
}

std::optional<std::string> ConcurrentBlasProblem(const BlasLibrary& blas) {
  if (blas.threading != "serial") return std::nullopt;
  return "the BLAS behind libblas.so.3 is OpenBLAS's serial build (" + blas.name +
         "), which returns wrong products when two threads call it at once, as "
         "handlabel's threads do; install its pthreads build (Debian: apt-get install "
         "libopenblas0-pthread, as scripts/install-deps does; it takes over the "
         "alternative) or select it: update-alternatives --config "
         "libblas.so.3-x86_64-linux-gnu";
}

std::optional<std::string> PrepareBlasForThreads() {
  if (const auto set_threads = OpenBlasFunction<void(int)>("openblas_set_num_threads")) {
    set_threads(1);
  }
  return ConcurrentBlasProblem(LoadedBlasLibrary());
}

}  // namespace handlabel
