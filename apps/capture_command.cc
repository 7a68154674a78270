// `handlabel capture init|import`: a real recording into the native capture layout
// (docs/real-captures.md). The work is in capture/capture_import.h.
#include <unistd.h>

#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "capture/capture_import.h"
#include "core/errors.h"
#include "core/progress.h"
#include "core/size_checks.h"

namespace handlabel {
namespace {

// "KEY=VALUE" -> (KEY, VALUE); throws InputError naming the flag.
std::pair<std::string, std::string> SplitAssignment(const std::string& text,
                                                    const std::string& flag,
                                                    const std::string& expected) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw InputError(flag, "value", expected, text);
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::map<std::string, int> ParseOffsets(const std::vector<std::string>& items) {
  std::map<std::string, int> offsets;
  for (const std::string& item : items) {
    const auto [camera, number] =
        SplitAssignment(item, "--offset", "CAMERA=N with an integer N");
    const int value = static_cast<int>(ParseIntegerInRange(
        number, "--offset", camera, "an integer frame offset", -1000000000, 1000000000));
    if (!offsets.emplace(camera, value).second) {
      throw InputError("--offset", camera, "one offset per camera", "two");
    }
  }
  return offsets;
}

std::map<std::string, std::string> ParseMap(const std::vector<std::string>& items) {
  std::map<std::string, std::string> map;
  for (const std::string& item : items) {
    const auto [source, camera] = SplitAssignment(item, "--map", "SOURCE=CAMERA");
    if (!map.emplace(source, camera).second) {
      throw InputError("--map", source, "one camera per source", "two");
    }
  }
  return map;
}

int RunCaptureInit(int argc, char** argv) {
  CLI::App app(
      "Make an empty native capture (docs/capture-format.md) from a calibrated rig: "
      "OUT/rig.json,\n"
      "OUT/colmap/ and OUT/capture.json with the rig's cameras and no frames yet. Then "
      "fill it\n"
      "with `handlabel capture import`. Guide: docs/real-captures.md\n"
      "Rig: FORMAT:PATH (json, colmap, colmap-text, colmap-bin, dexycb, ho3d, oakink), "
      "or a\n"
      "path: a rig .json file, a folder holding rig.json (`calib board` / `calib colmap` "
      "output)\n"
      "or a COLMAP model folder.\n"
      "Example: handlabel capture init --rig calib_out --out captures/session1",
      "capture init");
  std::string rig_text, out;
  CaptureInitOptions o;
  app.add_option("--rig", rig_text, "the calibrated rig (see above)")->required();
  app.add_option("--out", out, "capture folder to create")->required();
  app.add_option("--hand-side", o.hand_side, "hand the recording shows: right or left")
      ->capture_default_str();
  app.add_option("--world", o.world,
                 "what the world frame is (free text; default: the rig file's)");
  app.add_flag("--overwrite", o.overwrite,
               "replace a capture already in --out (its images are removed)");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("capture init", [&] {
    const RigSpec spec = ResolveRigSpec(rig_text, "--rig");
    o.rig_source = spec.format + ":" + spec.path;
    RigFileInfo info;
    const Rig rig = ReadRig(spec, &info);
    InitCapture(rig, info, out, o);
    std::cout << "made an empty capture with " << rig.size() << " cameras in " << out
              << " (rig from " << o.rig_source << ")\nnext: handlabel capture import "
              << "--capture " << out << " --images DIR | --videos DIR\n";
    return 0;
  });
}

int RunCaptureImport(int argc, char** argv) {
  CLI::App app(
      "Fill a capture made by `capture init` with a recording: one folder of images per "
      "camera\n"
      "(--images DIR: DIR/<camera>/<frame>.png|jpg|...) or one video per camera "
      "(--videos DIR:\n"
      "DIR/<camera>.mp4|mkv|avi|...; decoded with FFmpeg). Sources are matched to "
      "rig\n"
      "cameras by name; --map SOURCE=CAMERA for others. Image frames are matched by file "
      "name\n"
      "(--match name: the names every camera has) or by sorted position (--match "
      "index);\n"
      "videos by frame index, with --offset CAMERA=N when camera CAMERA started N frames "
      "early\n"
      "(its frame t+N belongs to frame t). Frames missing in a camera are left out, with "
      "a note.\n"
      "Images are written as PNG, atomically; capture.json lists the frames done every "
      "few\n"
      "frames, so an interrupted import keeps them and --resume continues it.\n"
      "Guide: docs/real-captures.md\n"
      "Example: handlabel capture import --capture captures/session1 --videos "
      "recordings/ --offset cam2=3 --stride 2",
      "capture import");
  std::string capture;
  std::vector<std::string> maps, offsets;
  CaptureImportOptions o;
  app.add_option("--capture", capture, "capture folder made by `capture init`")
      ->required();
  app.add_option("--images", o.images_dir,
                 "folder with one sub-folder of images per camera");
  app.add_option("--videos", o.videos_dir, "folder with one video per camera");
  app.add_option("--match", o.match,
                 "name or index (default: name for --images, index for --videos)");
  app.add_option("--map", maps,
                 "SOURCE=CAMERA: folder or video (name without extension) SOURCE holds "
                 "camera CAMERA; repeatable");
  app.add_option("--offset", offsets,
                 "CAMERA=N: camera CAMERA's frame t+N is frame t (index matching; N may "
                 "be negative); repeatable");
  app.add_option("--start", o.start, "first frame position to import")
      ->capture_default_str();
  app.add_option("--end", o.end, "stop before this frame position (-1: to the end)")
      ->capture_default_str();
  app.add_option("--stride", o.stride, "import every N-th frame")->capture_default_str();
  app.add_option("--max-frames", o.max_frames, "import at most N frames (0 = all)")
      ->capture_default_str();
  app.add_flag("--allow-mixed-fps", o.allow_mixed_fps,
               "pair videos of different frame rates by index all the same (refused "
               "without it)");
  app.add_flag("--resume", o.resume,
               "continue an interrupted import with the same sources and options");
  app.add_flag("--overwrite", o.overwrite,
               "discard the frames already imported and import again");
  app.add_option("--threads", o.num_threads, "worker threads, 0 = all cores")
      ->capture_default_str();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("capture import", [&] {
    o.source_to_camera = ParseMap(maps);
    o.offsets = ParseOffsets(offsets);
    // Made once the plan is known (the first call, before any frame is read); counts
    // only the frames of this run, so a resumed import's rate and ETA are its own.
    std::unique_ptr<Progress> progress;
    int kept = 0;
    CaptureImportCallbacks callbacks;
    callbacks.note = [](const std::string& text) {
      std::cerr << "handlabel capture import: note: " << text << "\n";
    };
    callbacks.progress = [&](int done, int total) {
      if (!progress) {
        kept = done;
        progress = std::make_unique<Progress>(
            total - kept, std::cerr, Progress::IsTerminal(STDERR_FILENO), "import");
        return;
      }
      progress->Update(done - kept);
    };
    const CaptureImportReport report = ImportCapture(capture, o, callbacks);
    if (progress) progress->Finish();
    std::cout << "imported " << report.frames_written << " frames";
    if (report.frames_kept > 0) {
      std::cout << " (" << report.frames_kept << " were already in the capture)";
    }
    std::cout << " into " << capture << ": " << report.frames_kept + report.frames_written
              << " of " << report.frames_total << " planned frames";
    if (report.stopped_early) std::cout << " (a video ended early, see the note)";
    std::cout << ", " << Progress::FormatDuration(report.seconds) << "\n";
    return 0;
  });
}

void PrintCaptureUsage(std::ostream& out) {
  out << "Usage: handlabel capture <init|import> [options]\n"
         "  init    --rig RIG --out DIR                  empty capture from a "
         "calibrated rig\n"
         "  import  --capture DIR --images|--videos DIR  fill it from image folders or "
         "videos\n"
         "Run 'handlabel capture <init|import> --help' for the options. Guide: "
         "docs/real-captures.md\n";
}

}  // namespace

int RunCapture(int argc, char** argv) {
  if (argc < 2) {
    PrintCaptureUsage(std::cerr);
    return 2;
  }
  const std::string sub = argv[1];
  if (sub == "--help" || sub == "-h") {
    PrintCaptureUsage(std::cout);
    return 0;
  }
  if (sub == "init") return RunCaptureInit(argc - 1, argv + 1);
  if (sub == "import") return RunCaptureImport(argc - 1, argv + 1);
  std::cerr << "handlabel capture: unknown subcommand '" << sub << "'\n";
  PrintCaptureUsage(std::cerr);
  return 2;
}

}  // namespace handlabel
