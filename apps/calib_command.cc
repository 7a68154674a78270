// `handlabel calib board|render-board|colmap`: calibrate a rig from board images or by
// SfM, or render a synthetic board capture to try board calibration without a rig.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "calib/board_calib_report.h"
#include "calib/board_images.h"
#include "calib/board_scale.h"
#include "calib/colmap_sfm.h"
#include "calib/rig_plot.h"
#include "calib/synthetic_board_capture.h"
#include "cameras/rig_io.h"
#include "core/errors.h"

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

int RunCalibRenderBoard(int argc, char** argv) {
  CLI::App app(
      "Render a synthetic board capture on a DexYCB-like rig (cameras on a ring around "
      "a\n"
      "table, 640x480), to try `calib board` without a rig. Writes OUT/images/<camera>/\n"
      "<frame>.png and the true rig OUT/truth.json.\n"
      "Example: handlabel calib render-board --out synthetic_capture",
      "calib render-board");
  std::string out, board_text = "charuco:11x8:0.03:0.022";
  SyntheticBoardCaptureOptions options;
  options.num_frames = 40;  // the configuration of the accuracy table in docs/cameras.md
  options.near_frames_per_camera = 16;
  BoardRenderOptions render;
  app.add_option("--out", out, "output folder (created)")->required();
  app.add_option("--board", board_text, "board spec")->capture_default_str();
  app.add_option("--cameras", options.num_cameras, "number of cameras")
      ->capture_default_str();
  app.add_option("--frames", options.num_frames, "board poses on the table")
      ->capture_default_str();
  app.add_option("--near-frames", options.near_frames_per_camera,
                 "board poses held in front of each camera")
      ->capture_default_str();
  app.add_option("--noise", render.noise_sigma, "pixel noise, grey levels")
      ->capture_default_str();
  app.add_option("--seed", options.seed, "random seed")->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("calib render-board", [&] {
    namespace fs = std::filesystem;
    const BoardSpec board = ParseBoardSpec(board_text, "--board");
    const SyntheticBoardCapture capture = SynthesizeBoardCapture(board, options);
    const int n = RenderBoardCapture(capture, board, (fs::path(out) / "images").string(),
                                     render, options.seed);
    RigFileInfo info;
    info.world = "table (synthetic truth)";
    WriteRig(capture.rig, {"json", (fs::path(out) / "truth.json").string()}, info);
    std::cout << "wrote " << n << " images to " << out << "/images and the true rig to "
              << out << "/truth.json\n";
    return 0;
  });
}

// The command line of `handlabel calib colmap`.
struct ColmapFlags {
  std::string images, out = "sfm_out", model = "OPENCV", scale;
  std::string board_spec, board_images, world = "camera";
  ColmapSfmOptions options;
};

void AddColmapOptions(CLI::App* app, ColmapFlags* f) {
  app->add_option("--images", f->images,
                  "folder with one sub-folder of images per camera")
      ->required();
  app->add_option("--out", f->out, "output folder (created)")->capture_default_str();
  app->add_option("--model", f->model, "COLMAP camera model for every camera")
      ->capture_default_str();
  app->add_option("--scale", f->scale,
                  "CAM_A,CAM_B,METRES: known distance between two camera centres");
  app->add_option("--board", f->board_spec,
                  "board for the scale, e.g. charuco:11x8:0.03:0.022 (docs/cameras.md)");
  app->add_option(
      "--board-images", f->board_images,
      "folder with <camera>/<frame> images of the board (cameras named as the "
      "--images folders; only cameras that see it)");
  app->add_option("--world", f->world, "camera (the master) or board (needs --board)")
      ->check(CLI::IsMember({"camera", "board"}))
      ->capture_default_str();
  app->add_option("--master", f->options.master,
                  "world = this camera (default: the first)");
  app->add_option("--colmap", f->options.colmap, "the colmap binary")
      ->capture_default_str();
  app->add_option("--threads", f->options.num_threads, "threads for COLMAP")
      ->capture_default_str();
}

// --scale CAM_A,CAM_B,METRES into the SfM options.
void ParseScale(const std::string& scale, ColmapSfmOptions* options) {
  const size_t c1 = scale.find(','), c2 = scale.rfind(',');
  try {
    if (c1 == std::string::npos || c1 == c2) throw std::invalid_argument(scale);
    options->camera_a = scale.substr(0, c1);
    options->camera_b = scale.substr(c1 + 1, c2 - c1 - 1);
    options->distance_m = std::stod(scale.substr(c2 + 1));
  } catch (const std::exception&) {
    throw InputError("--scale", "CAM_A,CAM_B,METRES", "e.g. cam0,cam1,0.412",
                     "'" + scale + "'");
  }
}

// One source of scale at most, the board with its images, a board world with a board.
void CheckScaleSources(const ColmapFlags& f) {
  if (!f.board_spec.empty() && !f.scale.empty()) {
    throw InputError("calib colmap", "--scale / --board", "one source of scale",
                     "both given");
  }
  if (f.board_spec.empty() != f.board_images.empty()) {
    throw InputError("calib colmap", "--board / --board-images", "both or neither",
                     f.board_spec.empty() ? "only --board-images" : "only --board");
  }
  if (f.world == "board" && f.board_spec.empty()) {
    throw InputError("calib colmap", "--world", "camera, or board with --board",
                     "board without --board");
  }
}

// Scales the SfM rig to metres from the board seen by several cameras at once and,
// for --world board, moves the world onto the board.
void ScaleByBoard(const ColmapFlags& f, const BoardSpec& board, ColmapSfmResult* result,
                  RigFileInfo* info) {
  std::cout << "detecting the board in " << f.board_images << "\n";
  const std::vector<CameraBoardViews> views =
      DetectBoardsInFolders(f.board_images, board, {}, &std::cout);
  const BoardScaleResult fix = ScaleFromBoard(result->rig, views, board, f.board_images);
  ScaleRig(&result->rig, fix.scale);
  result->scale = fix.scale;
  std::cout << "board scale from " << fix.corners << " corners in " << fix.frames
            << " frames (" << fix.pairs << " pairs, spread " << 100 * fix.spread
            << " %)\n";
  if (f.world == "board") {
    SetWorldToBoard(&result->rig, fix.world_from_board);
    info->world = "board in frame " + fix.board_frame;
  }
}

// OUT/rig.json, OUT/colmap/ and OUT/rig.png, and the summary on stdout.
void WriteColmapRig(const ColmapSfmResult& result, const RigFileInfo& info,
                    const std::string& out) {
  namespace fs = std::filesystem;
  WriteRig(result.rig, {"json", (fs::path(out) / "rig.json").string()}, info);
  WriteRig(result.rig, {"colmap-text", (fs::path(out) / "colmap").string()}, info);
  RigPlotOptions plot;
  plot.title = "COLMAP rig, world " + info.world;
  PlotRig(result.rig, (fs::path(out) / "rig.png").string(), plot);
  std::cout << result.registered << " of " << result.images
            << " images registered; scale " << result.scale << " m per COLMAP unit\n"
            << RigTable(result.rig) << "wrote " << out
            << "/{rig.json, colmap/, rig.png}\n";
}

int RunCalibColmap(int argc, char** argv) {
  CLI::App app(
      "Calibrate a static rig by structure from motion with the colmap binary (CPU):\n"
      "feature_extractor (one camera per folder), exhaustive_matcher, mapper. Needs one\n"
      "image per camera of a static, well-textured scene: IMAGES/<camera>/<image>.\n"
      "Scale comes from --scale CAM_A,CAM_B,METRES (the distance of two camera "
      "centres)\n"
      "or from a board seen by 2+ cameras at once: --board SPEC --board-images DIR\n"
      "(DIR/<camera>/<frame>.png, same frame names = same moment; --world board puts\n"
      "the world on the board of the first such frame).\n"
      "Writes OUT/rig.json, OUT/colmap/ (rig as a text model), OUT/rig.png; COLMAP's "
      "own\n"
      "database, logs and model stay in OUT/colmap_work.\n"
      "Example: handlabel calib colmap --images scene/ --scale cam0,cam1,0.412 --out "
      "sfm_out",
      "calib colmap");
  ColmapFlags f;
  AddColmapOptions(&app, &f);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("calib colmap", [&] {
    namespace fs = std::filesystem;
    ColmapSfmOptions& options = f.options;
    options.model = CameraModelFromName(f.model, "--model");
    options.work_dir = (fs::path(f.out) / "colmap_work").string();
    if (!f.scale.empty()) ParseScale(f.scale, &options);
    CheckScaleSources(f);
    const BoardSpec board =
        f.board_spec.empty() ? BoardSpec() : ParseBoardSpec(f.board_spec);
    std::cout << "running colmap on " << f.images << "\n";
    ColmapSfmResult result = CalibrateWithColmap(f.images, options, &std::cout);
    fs::create_directories(f.out);
    RigFileInfo info;
    info.world = "camera:" + result.rig[0].name;
    if (!options.master.empty()) info.world = "camera:" + options.master;
    if (!f.board_spec.empty()) {
      ScaleByBoard(f, board, &result, &info);
    } else if (options.camera_a.empty()) {
      info.world += " (COLMAP units, scale unknown)";
    }
    WriteColmapRig(result, info, f.out);
    return 0;
  });
}

void PrintCalibUsage(std::ostream& out) {
  out << "Usage: handlabel calib <board|render-board|colmap> [options]\n"
         "  board   --images DIR --board SPEC [--out DIR]   calibrate from board images\n"
         "  render-board --out DIR                         synthetic board images to try "
         "it\n"
         "  colmap  --images DIR [--scale A,B,METRES | --board SPEC --board-images DIR]\n"
         "                                                 calibrate by SfM with colmap\n"
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
  if (sub == "render-board") return RunCalibRenderBoard(argc - 1, argv + 1);
  if (sub == "colmap") return RunCalibColmap(argc - 1, argv + 1);
  std::cerr << "handlabel calib: unknown subcommand '" << sub << "'\n";
  PrintCalibUsage(std::cerr);
  return 2;
}

}  // namespace handlabel
