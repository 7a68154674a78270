// Loading time of hand model files: a MANO-sized model (778 vertices, 1538 faces, 10
// betas, random values) in the official pickle layout and in the handlabel npz, plus
// the pickle decoding alone and saving. Files go to a fresh folder under /tmp.
//
//   ./build/bench/hand_model_io_bench

#include <benchmark/benchmark.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "formats/pickle_reader.h"
#include "hand/hand_model_io.h"
#include "tests/hand/mano_sized_model.h"

namespace handlabel {
namespace {

struct Files {
  HandModel model;
  std::string dir, pickle, npz, pickle_bytes;
};

const Files& GetFiles() {
  static const Files files = [] {
    Files f;
    char pattern[] = "/tmp/hand_model_io_bench.XXXXXX";
    f.dir = mkdtemp(pattern);
    f.model = testing::RandomManoSizedModel(1);
    f.pickle = f.dir + "/MANO_RIGHT.pkl";
    f.npz = f.dir + "/mano_right.npz";
    f.pickle_bytes = testing::ManoStylePickle(f.model);
    std::ofstream(f.pickle, std::ios::binary) << f.pickle_bytes;
    SaveHandModel(f.model, f.npz);
    return f;
  }();
  return files;
}

void BM_LoadManoPickle(benchmark::State& state) {
  const Files& f = GetFiles();
  for (auto _ : state) benchmark::DoNotOptimize(LoadHandModel(f.pickle));
  state.SetBytesProcessed(state.iterations() * f.pickle_bytes.size());
}
BENCHMARK(BM_LoadManoPickle)->Unit(benchmark::kMillisecond);

void BM_DecodePickleOnly(benchmark::State& state) {
  const Files& f = GetFiles();
  for (auto _ : state) benchmark::DoNotOptimize(ReadPickle(f.pickle_bytes, "bench"));
  state.SetBytesProcessed(state.iterations() * f.pickle_bytes.size());
}
BENCHMARK(BM_DecodePickleOnly)->Unit(benchmark::kMillisecond);

void BM_LoadOwnNpz(benchmark::State& state) {
  const Files& f = GetFiles();
  for (auto _ : state) benchmark::DoNotOptimize(LoadHandModel(f.npz));
  state.counters["file_kb"] = std::filesystem::file_size(f.npz) / 1024.0;
}
BENCHMARK(BM_LoadOwnNpz)->Unit(benchmark::kMillisecond);

void BM_SaveOwnNpz(benchmark::State& state) {
  const Files& f = GetFiles();
  const std::string out = f.dir + "/saved.npz";
  for (auto _ : state) SaveHandModel(f.model, out);
}
BENCHMARK(BM_SaveOwnNpz)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace handlabel
