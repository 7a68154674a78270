#include <algorithm>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>

#include "apps/commands.h"
#include "core/blas_library.h"

namespace handlabel {
namespace {

void PrintUsage(std::ostream& out) {
  out << "handlabel: offline auto-labeling of multi-view hand captures\n\n"
         "Usage: handlabel <command> [options]\n"
         "       handlabel <command> --help   options of one command\n\n"
         "Commands:\n";
  for (const Command& c : AllCommands()) {
    std::string name = c.name;
    name.resize(std::max<size_t>(name.size(), 12), ' ');
    out << "  " << name << "  " << c.summary << "\n";
  }
  out << "\nDocumentation: README.md and docs/ in the source tree.\n";
}

}  // namespace

const std::vector<Command>& AllCommands() {
  static const std::vector<Command> commands = {
      {"version", "print version, git hash and dependency versions", RunVersion},
      {"model", "inspect and convert hand model files (MANO, smplx npz, own)", RunModel},
      {"label", "label a capture as a job (YAML), resumable, shardable", RunLabel},
      {"merge", "join the shards of a labeling job (manifest + summary)", RunMerge},
      {"smooth", "smooth a labelled sequence over time (windows, one shape)", RunSmooth},
      {"export", "labels as npz / csv (MANO parameters), COCO, glTF, DexYCB or HO3D",
       RunExport},
      {"cameras", "convert and show camera rigs (COLMAP, JSON, DexYCB, HO3D, OakInk)",
       RunCameras},
      {"calib", "calibrate a camera rig from board images or with COLMAP", RunCalib},
      {"capture", "make a capture from a rig and import image folders or videos",
       RunCapture},
      {"synth", "generate a synthetic multi-view hand capture with ground truth",
       RunSynth},
      {"fit", "fit the hand model to a capture's 2D keypoints and masks (Ceres)", RunFit},
      {"train", "train the POEM network on synthetic captures or labelled ones",
       RunTrain},
      {"adapt", "teach the network your rig from its own fit labels, then label it",
       RunAdapt},
      {"eval-network", "MPJPE / MPVPE / AUC of POEM weights on held-out synthetic frames",
       RunEvalNetwork},
      {"detect", "MediaPipe Hands 2D keypoints: a capture's views (multi-view) or images",
       RunDetect},
      {"compare", "run every method on the same frames: the paper's table, HTML report",
       RunCompare},
  };
  return commands;
}

int RunHandlabel(int argc, char** argv) {
  if (argc < 2) {
    PrintUsage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(std::cout);
    return 0;
  }
  if (name == "--version") return RunVersion(argc - 1, argv + 1);
  // Before any command computes (help and version print only).
  const bool computes =
      name != "version" && std::none_of(argv + 2, argv + argc, [](const char* a) {
        return std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0;
      });
  if (computes) {
    if (const std::optional<std::string> problem = PrepareBlasForThreads()) {
      std::cerr << "handlabel: " << *problem << "\n";
      return 2;
    }
  }
  for (const Command& c : AllCommands()) {
    if (name == c.name) return c.run(argc - 1, argv + 1);
  }
  std::cerr << "handlabel: unknown command '" << name << "'\n"
            << "Run 'handlabel --help' for the list of commands.\n";
  return 2;
}

}  // namespace handlabel
