// The benchmarks' main: the BLAS prepared as the program prepares it
// (apps/command_table.cc), so that products run on the caller's thread as in a job.
#include <benchmark/benchmark.h>

#include <iostream>

#include "core/blas_library.h"

int main(int argc, char** argv) {
  if (const auto problem = handlabel::PrepareBlasForThreads()) {
    std::cerr << "warning: " << *problem << "\n";
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
