#include "calib/colmap_sfm.h"

#include "calib/board_scale.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <ostream>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void RunStep(const std::string& name, const std::string& command,
             const fs::path& log_file, std::ostream* log) {
  if (log) *log << "  colmap " << name << " (log: " << log_file.string() << ")\n";
  const std::string full = command + " > " + Quote(log_file.string()) + " 2>&1";
  if (std::system(full.c_str()) != 0) {
    throw InputError("colmap " + name, "(exit status)", "success",
                     "failed, see " + log_file.string());
  }
}

}  // namespace

void ColmapSfmOptions::Check(const std::string& source) const {
  if (work_dir.empty()) throw InputError(source, "work_dir", "a folder for the database");
  RequireAtLeast(source, "num_threads", num_threads, 1);
  if (camera_a.empty() != camera_b.empty()) {
    throw InputError(source, "camera_a/camera_b", "both camera names or neither");
  }
  if (!camera_a.empty()) {
    RequireGreater(source, "distance_m", distance_m, 0, "a positive distance in metres");
  }
}

double FixRigScale(Rig* rig, const std::string& a, const std::string& b, double distance,
                   const std::string& source) {
  const double d = (rig->Find(a).CenterInWorld() - rig->Find(b).CenterInWorld()).norm();
  if (!(d > 1e-12)) {
    throw InputError(source, "scale cameras", "two cameras at different places",
                     a + " and " + b + " coincide");
  }
  const double scale = distance / d;
  ScaleRig(rig, scale);
  return scale;
}

ColmapSfmResult CalibrateWithColmap(const std::string& images_dir,
                                    const ColmapSfmOptions& options, std::ostream* log) {
  options.Check("ColmapSfmOptions");
  if (!fs::is_directory(images_dir)) {
    throw InputError(images_dir, "--images", "a folder with one sub-folder per camera",
                     "not a folder");
  }
  // Camera folders and the first image of each.
  std::map<std::string, std::string> first_image;  // folder -> relative image name
  int images = 0;
  for (const auto& dir : fs::directory_iterator(images_dir)) {
    if (!dir.is_directory()) continue;
    std::vector<std::string> names;
    for (const auto& f : fs::directory_iterator(dir.path())) {
      if (f.is_regular_file()) names.push_back(f.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    images += static_cast<int>(names.size());
    if (!names.empty())
      first_image[dir.path().filename().string()] =
          dir.path().filename().string() + "/" + names.front();
  }
  if (first_image.size() < 2) {
    throw InputError(images_dir, "--images", "at least two camera folders with images",
                     std::to_string(first_image.size()));
  }
  const fs::path work(options.work_dir);
  fs::create_directories(work / "sparse");
  const std::string db = (work / "database.db").string();
  fs::remove(db);
  const std::string colmap = Quote(options.colmap);
  const std::string threads = std::to_string(options.num_threads);
  RunStep("feature_extractor",
          colmap + " feature_extractor --database_path " + Quote(db) + " --image_path " +
              Quote(images_dir) +
              " --ImageReader.single_camera_per_folder 1 --ImageReader.camera_model " +
              CameraModelName(options.model) + " --SiftExtraction.use_gpu 0" +
              " --SiftExtraction.num_threads " + threads,
          work / "feature_extractor.log", log);
  RunStep("exhaustive_matcher",
          colmap + " exhaustive_matcher --database_path " + Quote(db) +
              " --SiftMatching.use_gpu 0 --SiftMatching.num_threads " + threads,
          work / "exhaustive_matcher.log", log);
  RunStep("mapper",
          colmap + " mapper --database_path " + Quote(db) + " --image_path " +
              Quote(images_dir) + " --output_path " + Quote((work / "sparse").string()) +
              " --Mapper.num_threads " + threads,
          work / "mapper.log", log);
  const fs::path model_dir = work / "sparse" / "0";
  if (!fs::exists(model_dir / "cameras.bin")) {
    throw InputError(
        "colmap mapper", "(model)", "a reconstruction in " + model_dir.string(),
        "none (too little texture or overlap?), see " + (work / "mapper.log").string());
  }
  ColmapSfmResult result;
  result.model = ReadColmapBinary(model_dir.string());
  result.images = images;
  result.registered = static_cast<int>(result.model.images.size());
  if (fs::exists(work / "sparse" / "1") && log) {
    *log << "  warning: COLMAP made several models; using sparse/0\n";
  }
  std::map<std::string, const ColmapImage*> by_name;
  for (const auto& [id, image] : result.model.images) by_name[image.name] = &image;
  std::string missing;
  for (const auto& [camera, image_name] : first_image) {
    const auto it = by_name.find(image_name);
    if (it == by_name.end()) {
      missing += (missing.empty() ? "" : ", ") + camera;
      continue;
    }
    const ColmapImage& image = *it->second;
    const ColmapCamera& cam = result.model.cameras.at(image.camera_id);
    result.rig.Add({camera,
                    Camera(cam.model, static_cast<int>(cam.width),
                           static_cast<int>(cam.height), cam.params, model_dir.string()),
                    image.cam_from_world});
  }
  if (!missing.empty()) {
    throw InputError("colmap mapper", "registered images",
                     "the first image of every camera folder in the model",
                     "not registered: [" + missing + "]");
  }
  if (!options.camera_a.empty()) {
    result.scale = FixRigScale(&result.rig, options.camera_a, options.camera_b,
                               options.distance_m, "--scale");
  }
  const std::string master = options.master.empty() ? result.rig[0].name : options.master;
  if (result.rig.IndexOf(master) < 0) {
    std::string known;
    for (const RigCamera& c : result.rig.cameras()) {
      known += (known.empty() ? "" : ", ") + c.name;
    }
    throw InputError("--master", "camera",
                     "one of the registered cameras [" + known + "]", "'" + master + "'");
  }
  result.rig.SetWorldToCamera(static_cast<size_t>(result.rig.IndexOf(master)));
  return result;
}

}  // namespace handlabel
