#pragma once
// The BLAS the process runs (the libblas.so.3 that LibTorch's products and Ceres'
// LAPACK call). handlabel calls it from several threads at once (frames in parallel, the
// network's two lanes, the detector beside the fit), which OpenBLAS's serial build does
// not survive: two threads calling it at once share its work buffers and get wrong
// products (measured: about 1 in 400 concurrent sgemm calls; a detector label job's
// labels then differed run to run in 4-8 of 72 real frames).
#include <optional>
#include <string>

namespace handlabel {

struct BlasLibrary {
  std::string name;  // "OpenBLAS 0.3.21 DYNAMIC_ARCH ..." or "unknown (not OpenBLAS)"
  // OpenBLAS's threading build: "serial", "pthreads", "openmp"; empty when not OpenBLAS.
  std::string threading;
};

// What libblas.so.3 resolved to in this process.
BlasLibrary LoadedBlasLibrary();

// Why `blas` cannot be called from several threads at once, or nothing when it can.
std::optional<std::string> ConcurrentBlasProblem(const BlasLibrary& blas);

// Prepares the process's BLAS for handlabel's threads: OpenBLAS's own thread pool set
// to one thread (every caller's products run on the caller's thread: the threads of
// the job, the detector and LibTorch already fill the cores, and a pool beside them
// spins against them). Returns ConcurrentBlasProblem of the loaded library.
std::optional<std::string> PrepareBlasForThreads();

}  // namespace handlabel
