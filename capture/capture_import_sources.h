#pragma once
// Internal to capture_import.cc: which recording belongs to which rig camera, and
// which of their images or video frames make which capture frame.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "capture/capture_import.h"
#include "media/frame_readers.h"

namespace handlabel {

// One frame to import: its id and, per camera (rig order), the position of its image
// in the camera's folder or its video frame index.
struct PlannedFrame {
  std::string id;
  std::vector<int> index;
};

// Name -> path of every source in `dir`: camera sub-folders, or video files by stem.
// `flag` names the option in messages.
std::map<std::string, std::filesystem::path> ListSources(const std::filesystem::path& dir,
                                                         bool videos,
                                                         const std::string& flag);

// Assigns a source to every rig camera: --map first, then sources named after a
// camera. Sources left over are reported in a note.
std::vector<CameraSource> MatchSources(
    const std::map<std::string, std::filesystem::path>& sources, const Rig& rig,
    const CaptureImportOptions& o, const std::filesystem::path& dir, bool videos,
    std::vector<std::string>* notes);

// Fills source->images (sorted); throws if the folder holds none.
void ListImages(CameraSource* source);

// Frames are the file stems every camera folder has, in sorted order.
std::vector<PlannedFrame> PlanByName(const std::vector<CameraSource>& cameras,
                                     const CaptureImportOptions& o,
                                     std::vector<std::string>* notes);

// Timeline frame t is camera c's own frame t + offset[c]; frames are the timeline
// positions every camera has (counts: frames per camera).
std::vector<PlannedFrame> PlanByIndex(const std::vector<CameraSource>& cameras,
                                      const std::vector<int>& counts,
                                      const CaptureImportOptions& o,
                                      std::vector<std::string>* notes);

}  // namespace handlabel
