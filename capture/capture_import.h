#pragma once
// Real recordings into the native capture layout (docs/capture-format.md,
// docs/real-captures.md), in two steps:
//
//   InitCapture    a rig -> an empty capture: rig.json, colmap/, capture.json (no frames)
//   ImportCapture  one image folder per camera, or one video per camera, -> the
//                  capture's images/{camera}/{frame}.png and frame list
//
// Frames are matched across cameras by file name (image folders) or by index with a
// per-camera offset (image folders or videos, OpenCV VideoCapture). Every image is
// written atomically, and capture.json is rewritten atomically every few frames with
// the frames whose images are all on disk: a killed import leaves a capture the native
// reader reads (with the frames done so far), and `resume` continues it.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cameras/rig_io.h"
#include "geometry/rig.h"
#include "image/image.h"

namespace handlabel {

// Where imported images go, relative to the capture folder.
inline constexpr char kImportImagePattern[] = "images/{camera}/{frame}.png";
inline constexpr char kImportImagesFolder[] = "images";

struct CaptureInitOptions {
  // Which hand the recording shows ("right" or "left"); labeling jobs build the hand
  // model for it.
  std::string hand_side = "right";
  // What the world frame is (free text); "" = the rig file's own `world`, if any.
  std::string world;
  // How the rig was named on the command line (FORMAT:PATH), recorded in the manifest.
  std::string rig_source;
  // Replace a capture already in the folder (its images/ folder is removed).
  bool overwrite = false;
  void Check(const std::string& source) const;
};

// The rig named by `text`: FORMAT:PATH (cameras/rig_io.h), or a bare path: a `.json` rig
// file, a folder holding `rig.json` (what `calib board` / `calib colmap` write), or a
// COLMAP model folder (cameras.txt or cameras.bin). Throws InputError naming `flag`.
RigSpec ResolveRigSpec(const std::string& text, const std::string& flag);

// Writes `out_dir`/rig.json, colmap/ (text model) and capture.json with the rig's
// cameras, no frames and the file kind "image". Throws InputError if `out_dir` already
// holds a capture (unless overwrite) or is a file.
void InitCapture(const Rig& rig, const RigFileInfo& rig_info, const std::string& out_dir,
                 const CaptureInitOptions& options);

struct CaptureImportOptions {
  // Exactly one source: a folder with one sub-folder of images per camera, or a folder
  // with one video per camera (file name without extension = camera).
  std::string images_dir;
  std::string videos_dir;
  // How frames are matched across cameras: "name" (the file names, without
  // extension, that every camera folder has) or "index" (the i-th image of each folder
  // by sorted name, the i-th frame of each video). "" = "name" for image folders,
  // "index" for videos (the only choice there).
  std::string match;
  // Source folder / video name -> rig camera, for sources not named after their camera.
  std::map<std::string, std::string> source_to_camera;
  // Camera -> offset: camera c's own frame t + offset[c] belongs to timeline frame t
  // (index matching only). Cameras not listed have offset 0.
  std::map<std::string, int> offsets;
  // Frames to import: positions [start, end) of the timeline (index matching) or of
  // the sorted common file names (name matching), every `stride`-th, at most
  // `max_frames` (0 = all). end = -1: until a camera runs out.
  int start = 0;
  int end = -1;
  int stride = 1;
  int max_frames = 0;
  // Videos whose declared frame rates differ (by more than 0.1 %) are paired by index
  // all the same, with a note naming them; without it they are refused: frame t of a
  // 15 fps and of a 30 fps video are not one moment.
  bool allow_mixed_fps = false;
  // Continue an interrupted import with the same sources and settings: frames already
  // in capture.json are kept and not read again.
  bool resume = false;
  // Discard frames already imported (removes images/) and import again. capture.json
  // then lists the new images only: detections, keypoints, masks, ground truth and any
  // other kind of file it listed describe the old ones (a note names them; their
  // files stay on disk). Nothing is dropped before the sources are found to give frames.
  bool overwrite = false;
  // capture.json is rewritten after every this many frames (what a killed import keeps).
  int checkpoint_frames = 20;
  // Worker threads over the cameras of a frame; 0 = TBB's default (all cores).
  int num_threads = 0;
  PngWriteOptions png;
  void Check(const std::string& source) const;
  // `match` with its default resolved.
  std::string Matching() const;
};

struct CaptureImportReport {
  int frames_total = 0;        // frames of the plan (after range, stride, max_frames)
  int frames_kept = 0;         // already in capture.json from an interrupted run (resume)
  int frames_written = 0;      // imported now
  bool stopped_early = false;  // a video ended before its declared length
  std::vector<std::string> notes;  // what was left out or differed, and why
  double seconds = 0;
};

struct CaptureImportCallbacks {
  // A note for the user (frame counts that differ, ignored folders, ...), as it arises.
  std::function<void(const std::string&)> note;
  // (frames done including kept ones, frames planned): once before the first frame is
  // read (done = the frames a resumed import keeps), then after every frame.
  std::function<void(int, int)> progress;
};

// Imports into the capture `capture_dir` made by InitCapture, holding the folder's
// writer lock (core/file_lock.h) throughout: another import, `capture init
// --overwrite` or `detect --capture` on the folder meanwhile is refused naming this
// one, and this one is refused while they run. Throws InputError for a
// rig camera without a source, videos of different frame rates (unless
// allow_mixed_fps), a damaged video frame or image file (naming the file and frame), an image whose size differs from its camera's (naming
// the file, the camera and both sizes), an unreadable image or video, a capture that
// already has frames (without resume / overwrite), or resume with other settings.
// Whatever frames were completely written before an error stay in capture.json.
CaptureImportReport ImportCapture(const std::string& capture_dir,
                                  const CaptureImportOptions& options,
                                  const CaptureImportCallbacks& callbacks = {});

}  // namespace handlabel
