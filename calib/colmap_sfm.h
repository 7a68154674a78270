#pragma once
// Calibration by structure from motion: drives the `colmap` binary (3.8) on one image
// per camera of a static, textured scene, reads the model and fixes its scale and
// frame.
//   colmap feature_extractor  --ImageReader.single_camera_per_folder 1 (one camera per
//                               folder), --ImageReader.camera_model MODEL,
//                               --SiftExtraction.use_gpu 0
//   colmap exhaustive_matcher --SiftMatching.use_gpu 0
//   colmap mapper
// Layout: IMAGES/<camera>/<image>; the first image (by name) of every camera folder
// gives that camera's pose (the rig is static, so all images of a folder share it).
// SfM has no scale: it is fixed from the known distance between two camera centres.

#include <iosfwd>
#include <string>

#include "cameras/colmap_model.h"
#include "geometry/rig.h"

namespace handlabel {

struct ColmapSfmOptions {
  std::string colmap = "colmap";  // the binary
  std::string work_dir;           // database and model go here (required)
  CameraModelId model = CameraModelId::kOpenCV;
  int num_threads = 2;  // for extraction, matching and mapping
  // Scale: the centres of camera_a and camera_b are `distance_m` apart. Empty names =
  // no scale fix (COLMAP's arbitrary unit).
  std::string camera_a, camera_b;
  double distance_m = 0;
  // World frame: this camera ("" = the first folder).
  std::string master;
  void Check(const std::string& source) const;
};

struct ColmapSfmResult {
  Rig rig;
  ColmapModel model;   // as COLMAP wrote it (unscaled)
  double scale = 1;    // metres per COLMAP unit
  int registered = 0;  // images COLMAP registered
  int images = 0;      // images offered
};

// Throws InputError naming the failing colmap step (with its log file), a camera whose
// images COLMAP could not register, or bad options.
ColmapSfmResult CalibrateWithColmap(const std::string& images_dir,
                                    const ColmapSfmOptions& options,
                                    std::ostream* log = nullptr);

// Scales a rig's translations so that the centres of cameras a and b are `distance`
// apart, then puts the world at `master` ("" = keep). Returns the scale applied.
double FixRigScale(Rig* rig, const std::string& a, const std::string& b, double distance,
                   const std::string& source);

}  // namespace handlabel
