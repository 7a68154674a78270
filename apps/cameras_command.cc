// `handlabel cameras convert|show`: rig files in every format users bring.
#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "calib/rig_plot.h"
#include "cameras/rig_compare.h"
#include "cameras/rig_io.h"
#include "core/text.h"

namespace handlabel {
namespace {

int RunCamerasConvert(int argc, char** argv) {
  CLI::App app(
      "Convert a rig between formats.\n"
      "Readable: " +
          Join(ReadableRigFormats()) + "\n" + "Writable: " + Join(WritableRigFormats()) +
          "\n"
          "Example: handlabel cameras convert --from colmap:sparse/0 --to json:rig.json",
      "cameras convert");
  std::string from, to;
  app.add_option("--from", from, "input rig as FORMAT:PATH")->required();
  app.add_option("--to", to, "output rig as FORMAT:PATH (folders are created)")
      ->required();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("cameras convert", [&] {
    const RigSpec in = ParseRigSpec(from, "--from");
    const RigSpec out = ParseRigSpec(to, "--to");
    RigFileInfo info;
    const Rig rig = ReadRig(in, &info);
    if (info.world.empty()) info.world = "as in " + from;
    WriteRig(rig, out, info);
    std::cout << "wrote " << rig.size() << " cameras to " << to << "\n";
    return 0;
  });
}

int RunCamerasShow(int argc, char** argv) {
  CLI::App app(
      "Print a rig as a table and optionally draw its camera frusta (from above and from "
      "the side) into a PNG.\n"
      "Formats: " +
          Join(ReadableRigFormats()) + "\n" +
          "Example: handlabel cameras show json:rig.json --plot rig.png",
      "cameras show");
  std::string spec, plot;
  RigPlotOptions plot_options;
  app.add_option("rig", spec, "rig as FORMAT:PATH")->required();
  app.add_option("--plot", plot, "write a PNG of the rig here");
  app.add_option(
      "--frustum-depth", plot_options.frustum_depth,
      "frustum depth in metres in the plot (default: 20 % of the rig's extent)");
  app.add_option("--panel-size", plot_options.panel_size,
                 "size of each of the two plot panels in pixels")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("cameras show", [&] {
    RigFileInfo info;
    const Rig rig = ReadRig(ParseRigSpec(spec, "rig"), &info);
    std::cout << rig.size() << " cameras from " << spec;
    if (!info.world.empty()) std::cout << " (world: " << info.world << ")";
    std::cout << "\n" << RigTable(rig);
    if (!plot.empty()) {
      plot_options.title = spec;
      PlotRig(rig, plot, plot_options);
      std::cout << "plot: " << plot << "\n";
    }
    return 0;
  });
}

int RunCamerasCompare(int argc, char** argv) {
  CLI::App app(
      "Compare two rigs camera by camera (e.g. a calibration against ground truth): "
      "focal\n"
      "length, principal point, rotation and camera centre. Both rigs are re-expressed "
      "with\n"
      "the world at the same reference camera first.\n"
      "Example: handlabel cameras compare json:calib_out/rig.json json:truth.json",
      "cameras compare");
  std::string a, b, reference;
  app.add_option("rig", a, "rig to check, FORMAT:PATH")->required();
  app.add_option("reference_rig", b, "reference rig (e.g. ground truth), FORMAT:PATH")
      ->required();
  app.add_option("--camera", reference,
                 "reference camera (default: the first of the reference rig)");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("cameras compare", [&] {
    const Rig rig_a = ReadRig(ParseRigSpec(a, "rig"));
    const Rig rig_b = ReadRig(ParseRigSpec(b, "reference_rig"));
    std::cout << RigDifferenceTable(CompareRigs(rig_a, rig_b, reference, a, b));
    return 0;
  });
}

void PrintCamerasUsage(std::ostream& out) {
  out << "Usage: handlabel cameras <convert|show|compare> [options]\n"
         "  convert  --from FORMAT:PATH --to FORMAT:PATH   convert a rig between "
         "formats\n"
         "  show     FORMAT:PATH [--plot PNG]             table and picture of a rig\n"
         "  compare  FORMAT:PATH FORMAT:PATH              per-camera differences of two "
         "rigs\n"
         "Formats: "
      << Join(ReadableRigFormats())
      << "\nRun 'handlabel cameras <convert|show|compare> --help' for the options. "
         "Guide: docs/cameras.md\n";
}

}  // namespace

int RunCameras(int argc, char** argv) {
  if (argc < 2) {
    PrintCamerasUsage(std::cerr);
    return 2;
  }
  const std::string sub = argv[1];
  if (sub == "--help" || sub == "-h") {
    PrintCamerasUsage(std::cout);
    return 0;
  }
  if (sub == "convert") return RunCamerasConvert(argc - 1, argv + 1);
  if (sub == "show") return RunCamerasShow(argc - 1, argv + 1);
  if (sub == "compare") return RunCamerasCompare(argc - 1, argv + 1);
  std::cerr << "handlabel cameras: unknown subcommand '" << sub << "'\n";
  PrintCamerasUsage(std::cerr);
  return 2;
}

}  // namespace handlabel
