// `handlabel calib board|colmap`: calibrate a rig from board images or by SfM.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "calib/board_calib_report.h"
#include "calib/board_images.h"
#include "calib/rig_io.h"
#include "calib/rig_plot.h"

namespace handlabel {
namespace {

int RunCalibBoard(int argc, char** argv) {
  CLI::App app(
      "Calibrate a multi-camera rig from images of a ChArUco board or checkerboard.\n"
      "Images: DIR/<camera>/<frame>.png; the same <frame> name in two camera folders\n"
      "means the same moment (the same board pose).\n"
      "Board: charuco:COLSxROWS:SQUARE:MARKER[:DICT] or checkerboard:COLSxROWS:SQUARE\n"
      "(COLSxROWS count squares, lengths in metres).\n"
      "Writes OUT/rig.json, OUT/colmap/ (text model), OUT/report.json,\n"
      "OUT/residuals.png and OUT/rig.png.\n"
      "Example: handlabel calib board --images capture/ --board charuco:7x5:0.04:0.03 "
      "--out calib_out",
      "calib board");
  std::string images, board_text, out = "calib_out", model = "OPENCV";
  BoardCalibOptions options;
  BoardDetectOptions detect;
  app.add_option("--images", images, "folder with one sub-folder of images per camera")
      ->required();
  app.add_option("--board", board_text, "board spec, see above")->required();
  app.add_option("--out", out, "output folder (created)")->capture_default_str();
  app.add_option("--model", model,
                 "camera model for every camera: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, "
                 "RADIAL, OPENCV, OPENCV_FISHEYE, FULL_OPENCV")
      ->capture_default_str();
  app.add_option("--master", options.master, "master camera (default: the first folder)");
  app.add_option("--world", options.world,
                 "world frame: camera (the master camera), board (the board in the first "
                 "frame the master saw) or board:FRAME")
      ->capture_default_str();
  app.add_option("--huber-px", options.huber_px, "Huber loss scale, pixels")
      ->capture_default_str();
  app.add_option("--outlier-rounds", options.outlier_rounds,
                 "rounds of outlier rejection after the first solve")
      ->capture_default_str();
  app.add_option("--outlier-sigmas", options.outlier_sigmas,
                 "residuals above this many robust sigmas are outliers")
      ->capture_default_str();
  app.add_option("--min-outlier-px", options.min_outlier_px,
                 "never call residuals below this many pixels outliers")
      ->capture_default_str();
  app.add_option("--min-frames", options.min_frames_per_camera,
                 "fewest images with the board found that a camera needs")
      ->capture_default_str();
  app.add_option("--min-corners", detect.min_corners,
                 "fewest corners for a detection to count")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("calib board", [&] {
    namespace fs = std::filesystem;
    const BoardSpec board = ParseBoardSpec(board_text, "--board");
    options.model = CameraModelFromName(model, "--model");
    std::cout << "detecting " << board.ToString() << " in " << images << "\n";
    const std::vector<CameraBoardViews> views =
        DetectBoardsInFolders(images, board, detect, &std::cout);
    const BoardCalibResult result = CalibrateBoardRig(views, board, options);
    fs::create_directories(out);
    RigFileInfo info;
    info.world = result.world;
    WriteRig(result.rig, {"json", (fs::path(out) / "rig.json").string()}, info);
    WriteRig(result.rig, {"colmap-text", (fs::path(out) / "colmap").string()}, info);
    std::ofstream((fs::path(out) / "report.json").string())
        << BoardCalibJson(result, board, options).dump(2) << "\n";
    PlotBoardResiduals(result, (fs::path(out) / "residuals.png").string());
    RigPlotOptions plot;
    plot.title = "calibrated rig, world " + result.world;
    for (const auto& [key, pose] : result.world_from_board) {
      for (const Eigen::Vector3d& c : board.Corners()) plot.points.push_back(pose * c);
    }
    PlotRig(result.rig, (fs::path(out) / "rig.png").string(), plot);
    std::cout << BoardCalibTable(result) << "wrote " << out
              << "/{rig.json, colmap/, report.json, residuals.png, rig.png}\n";
    return 0;
  });
}

void PrintCalibUsage(std::ostream& out) {
  out << "Usage: handlabel calib <board|colmap> [options]\n"
         "  board   --images DIR --board SPEC [--out DIR]   calibrate from board images\n"
         "Run 'handlabel calib <board|colmap> --help' for the options. Guide: "
         "docs/cameras.md\n";
}

}  // namespace

int RunCalib(int argc, char** argv) {
  if (argc < 2) {
    PrintCalibUsage(std::cerr);
    return 2;
  }
  const std::string sub = argv[1];
  if (sub == "--help" || sub == "-h") {
    PrintCalibUsage(std::cout);
    return 0;
  }
  if (sub == "board") return RunCalibBoard(argc - 1, argv + 1);
  std::cerr << "handlabel calib: unknown subcommand '" << sub << "'\n";
  PrintCalibUsage(std::cerr);
  return 2;
}

}  // namespace handlabel
