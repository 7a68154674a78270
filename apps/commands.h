#pragma once
// The `handlabel` subcommands. Each is `int RunX(int argc, char** argv)` where argv[0]
// is the subcommand name; exit status 0 = success, 1 = the work failed (message on
// stderr), 2 = bad usage.

#include <vector>

namespace handlabel {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);
};

// The table, in the order `handlabel --help` lists it.
const std::vector<Command>& AllCommands();

// Dispatches argv[1] to its subcommand; argv[0] is the program name.
int RunHandlabel(int argc, char** argv);

int RunVersion(int argc, char** argv);
int RunModel(int argc, char** argv);
// `model build` / `model render` (apps/model_build_command.cc).
int RunModelBuild(int argc, char** argv);
int RunModelRender(int argc, char** argv);
int RunModelExport(int argc, char** argv);
// `model detector-keypoints` (apps/model_detector_keypoints_command.cc).
int RunModelDetectorKeypoints(int argc, char** argv);
int RunLabel(int argc, char** argv);
int RunMerge(int argc, char** argv);
int RunSmooth(int argc, char** argv);
int RunExport(int argc, char** argv);
int RunCameras(int argc, char** argv);
int RunCalib(int argc, char** argv);
int RunCapture(int argc, char** argv);
int RunSynth(int argc, char** argv);
int RunFit(int argc, char** argv);
int RunTrain(int argc, char** argv);
int RunAdapt(int argc, char** argv);
int RunEvalNetwork(int argc, char** argv);
int RunDetect(int argc, char** argv);
int RunCompare(int argc, char** argv);

}  // namespace handlabel
