#include "capture/synth_capture.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "cameras/colmap_model.h"
#include "cameras/colmap_rig.h"
#include "cameras/rig_json.h"
#include "capture/capture_format.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "core/version.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

enum Stream : uint64_t {
  kSceneStream = 1,
  kBackgroundStream = 2,
  kDetectionStream = 3,
  kAppearanceStream = 4,  // the realistic look's own draws (the scene stays the same)
};

// Frame files are plain writes (no fsync): the manifest, written atomically last,
// is what marks a capture complete.
void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw Error("cannot write " + path);
}

ImageU16 DepthToU16(const ImageF& depth, double unit) {
  ImageU16 out(depth.width, depth.height, 1);
  for (size_t i = 0; i < depth.data.size(); ++i) {
    const double steps = std::round(depth.data[i] / unit);
    out.data[i] = static_cast<uint16_t>(std::clamp(steps, 0.0, 65535.0));
  }
  return out;
}

}  // namespace

void SynthCaptureOptions::Check(const std::string& source) const {
  // The parts keep their own names in messages, as their fields are theirs.
  rig.Check("rig options");
  scene.Check("synthetic scene options");
  sequence.Check("synthetic sequence options");
  view.Check("synthetic view options");
  detections.Check("detection noise options");
  RequireInRange(source, "num_frames", num_frames, 1, 100000000, "1..1e8");
  RequireAtLeast(source, "num_threads", num_threads, 0, ">= 0 (0 = all cores)");
  RequireInRange(source, "png.compression_level", png.compression_level, 0, 9);
}

SynthGenerator::SynthGenerator(const HandModel& model, Rig rig,
                               const SynthCaptureOptions& options)
    : model_(model), rig_(std::move(rig)), options_(options) {
  // The photographs show the real table: the look's own would hide it.
  if (options_.view.photo_backgrounds) options_.view.realistic.table = false;
  options_.Check("synth options");
  if (rig_.empty()) throw InputError("synth", "rig", "at least one camera", "none");
  anatomy_ = ComputeHandAnatomy(model_);
  limits_ = DefaultHandLimits();
  for (const RigCamera& cam : rig_.cameras()) rays_.emplace_back(cam.camera);
  CheckPhotoBackgrounds();
}

void SynthGenerator::CheckPhotoBackgrounds() const {
  const auto& photos = options_.view.photo_backgrounds;
  if (!photos) return;
  if (photos->size() != rig_.size()) {
    throw InputError("synth options", "view.photo_backgrounds",
                     "one per rig camera (" + std::to_string(rig_.size()) + ")",
                     std::to_string(photos->size()));
  }
  for (size_t c = 0; c < rig_.size(); ++c) {
    const ImageU8& photo = (*photos)[c];
    const Camera& camera = rig_[c].camera;
    if (photo.width != camera.width() || photo.height != camera.height() ||
        photo.channels != 3) {
      throw InputError(
          "synth options", "view.photo_backgrounds[" + std::to_string(c) + "]",
          "RGB of camera " + rig_[c].name + "'s size " + std::to_string(camera.width()) +
              " x " + std::to_string(camera.height()),
          std::to_string(photo.width) + " x " + std::to_string(photo.height) + " x " +
              std::to_string(photo.channels));
    }
  }
}

SynthFrame SynthGenerator::Generate(int index) const {
  SynthFrame frame;
  frame.index = index;
  const SynthSequenceOptions& sequence = options_.sequence;
  if (sequence.enabled) {
    frame.scene =
        SampleSynthSequenceScene(model_, anatomy_, limits_, rig_, options_.scene,
                                 sequence, options_.seed, index / sequence.fps);
  } else {
    std::mt19937_64 scene_rng(MixSeed(options_.seed, index, kSceneStream));
    frame.scene =
        SampleSynthScene(model_, anatomy_, limits_, rig_, options_.scene, scene_rng);
  }
  // A sequence is one scene before fixed cameras: every frame takes frame 0's look
  // and backgrounds (their sensor noise included), so nothing but the motion changes.
  const int look_index = sequence.enabled ? 0 : index;
  if (options_.view.appearance == SynthAppearance::kRealistic) {
    std::mt19937_64 look_rng(MixSeed(options_.seed, look_index, kAppearanceStream));
    ApplyRealisticLook(model_, options_.view.realistic, look_rng, &frame.scene);
  }
  for (size_t c = 0; c < rig_.size(); ++c) {
    std::mt19937_64 bg_rng(
        MixSeed(options_.seed, look_index, kBackgroundStream + 16 * c));
    const ImageU8* photo = options_.view.photo_backgrounds
                               ? &(*options_.view.photo_backgrounds)[c]
                               : nullptr;
    frame.views.push_back(
        RenderSynthView(frame.scene, rig_[c], rays_[c], options_.view, bg_rng, photo));
    if (options_.write_detections) {
      std::mt19937_64 det_rng(MixSeed(options_.seed, index, kDetectionStream + 16 * c));
      frame.detections.push_back(
          SimulateDetections(frame.views.back(), options_.detections, det_rng));
    }
  }
  return frame;
}

nlohmann::json SynthOptionsToJson(const SynthCaptureOptions& o) {
  nlohmann::json j;
  j["num_frames"] = o.num_frames;
  j["seed"] = o.seed;
  j["rig"] = {{"preset", o.rig.preset},
              {"width", o.rig.width},
              {"height", o.rig.height},
              {"num_cameras", o.rig.num_cameras},
              {"distance", {o.rig.min_distance, o.rig.max_distance}},
              {"elevation_deg", {o.rig.min_elevation_deg, o.rig.max_elevation_deg}},
              {"azimuth_span_deg", o.rig.azimuth_span_deg},
              {"fov_deg", {o.rig.min_fov_deg, o.rig.max_fov_deg}},
              {"distortion", o.rig.distortion}};
  const SynthSceneOptions& s = o.scene;
  j["scene"] = {
      {"pose_weights",
       {{"open", s.weight_open},
        {"fist", s.weight_fist},
        {"pinch", s.weight_pinch},
        {"point", s.weight_point},
        {"random", s.weight_random},
        {"grasp", s.weight_grasp},
        {"pca", s.weight_pca}}},
      {"jitter_deg", s.jitter_deg},
      {"pca_sigma", s.pca_sigma},
      {"pca_components", s.pca_components},
      {"betas_sigma", s.betas_sigma},
      {"objects", s.objects},
      {"max_objects", s.max_objects},
      {"workspace_center",
       {s.workspace_center.x(), s.workspace_center.y(), s.workspace_center.z()}},
      {"workspace_radius", s.workspace_radius},
      {"placement_tries", s.placement_tries}};
  j["view"] = {{"clutter", o.view.background.clutter},
               {"max_shapes", o.view.background.max_shapes},
               {"max_noise", o.view.background.max_noise},
               {"self_occlusion_tolerance", o.view.self_occlusion_tolerance}};
  // Recorded only when not the default, so that basic captures stay byte-identical
  // to those made before the option existed (absent = basic).
  if (o.view.appearance != SynthAppearance::kBasic) {
    j["view"]["appearance"] = SynthAppearanceName(o.view.appearance);
  }
  const DetectionNoiseOptions& d = o.detections;
  j["detections"] = {{"enabled", o.write_detections},
                     {"keypoint_sigma_px", d.keypoint_sigma_px},
                     {"outlier_rate", d.outlier_rate},
                     {"dropout_rate", d.dropout_rate},
                     {"occluded_dropout_rate", d.occluded_dropout_rate},
                     {"mask_morph_radius", d.mask_morph_radius},
                     {"mask_blobs", d.mask_blobs}};
  j["depth"] = o.write_depth;
  // Recorded only for sequences: independent captures stay byte-identical.
  if (o.sequence.enabled) {
    const SynthSequenceOptions& q = o.sequence;
    j["sequence"] = {{"fps", q.fps},
                     {"reach_seconds", q.reach_seconds},
                     {"grasp_seconds", q.grasp_seconds},
                     {"carry_seconds", q.carry_seconds},
                     {"release_seconds", q.release_seconds},
                     {"motion_radius", q.motion_radius},
                     {"rotation_range_deg", q.rotation_range_deg}};
  }
  return j;
}

namespace {

// Refuses a file, or a folder holding a capture unless `overwrite`; removes the old
// manifest, which must not describe half-rewritten frames.
void PrepareOutputFolder(const std::string& out_dir, bool overwrite) {
  const fs::path root(out_dir);
  const fs::path manifest_path = root / kCaptureManifestFile;
  if (fs::exists(root) && !fs::is_directory(root)) {
    throw InputError(out_dir, "--out", "a folder (or a path to create)",
                     "an existing file");
  }
  if (fs::exists(manifest_path) && !overwrite) {
    throw InputError(out_dir, "--out", "a folder without a capture (or --overwrite)",
                     "it already holds " + std::string(kCaptureManifestFile));
  }
  if (fs::exists(manifest_path)) fs::remove(manifest_path);
}

CaptureManifest MakeManifest(const HandModel& model, const SynthCaptureOptions& options,
                             const Rig& rig, const std::string& hand_model_source) {
  CaptureManifest manifest;
  manifest.colmap_dir = "colmap";
  manifest.world = "table frame: z up, origin at the workspace centre, metres";
  manifest.hand_side = HandSideName(model.side);
  for (const RigCamera& cam : rig.cameras()) manifest.cameras.push_back(cam.name);
  for (int f = 0; f < options.num_frames; ++f) manifest.frames.push_back(FrameId(f));
  manifest.files[kFileImage] = "images/{camera}/{frame}.png";
  manifest.files[kFileMask] = "masks/{camera}/{frame}.png";
  manifest.files[kFileKeypoints] = "keypoints/{frame}.json";
  manifest.files[kFileGroundTruth] = "ground_truth/{frame}.json";
  if (options.scene.objects)
    manifest.files[kFileObjectMask] = "object_masks/{camera}/{frame}.png";
  if (options.write_depth) manifest.files[kFileDepth] = "depth/{camera}/{frame}.png";
  if (options.write_detections) {
    manifest.files[kFileDetections] = "detections/{frame}.json";
    manifest.files[kFileDetectionMask] = "detections/masks/{camera}/{frame}.png";
  }
  manifest.generator = {
      {"tool", "handlabel synth"},
      {"handlabel_version", HandlabelVersion()},
      {"seed", options.seed},
      {"hand_model", {{"name", model.name}, {"source", hand_model_source}}},
      {"settings", SynthOptionsToJson(options)}};
  return manifest;
}

// Folders first, so that worker threads only write files; then the rig files.
void WriteCaptureFolders(const fs::path& root, const CaptureManifest& manifest,
                         const Rig& rig) {
  fs::create_directories(root / manifest.colmap_dir);
  for (const auto& [kind, pattern] : manifest.files) {
    for (const std::string& cam : manifest.cameras) {
      fs::create_directories((root / ExpandPattern(pattern, cam, "x")).parent_path());
    }
  }
  RigFileInfo info;
  info.world = manifest.world;
  WriteRigJson(rig, (root / manifest.rig_file).string(), info);
  WriteColmapText(ColmapFromRig(rig), (root / manifest.colmap_dir).string());
}

// Writes every file of frame f; returns its views counted as visible, occluded and
// out of frame. Thread-safe for different frames.
std::array<int, 3> WriteFrameFiles(const SynthGenerator& generator,
                                   const CaptureManifest& manifest, const fs::path& root,
                                   const SynthCaptureOptions& options,
                                   const HandModel& model, int f) {
  const Rig& rig = generator.rig();
  const SynthFrame frame = generator.Generate(f);
  const std::string id = FrameId(f);
  auto path = [&](const char* kind, const std::string& cam) {
    return (root / ExpandPattern(manifest.files.at(kind), cam, id)).string();
  };
  std::array<int, 3> status_counts{};
  std::vector<ViewKeypoints> gt2d, det2d;
  for (size_t c = 0; c < rig.size(); ++c) {
    const std::string& cam = rig[c].name;
    const SynthView& view = frame.views[c];
    WriteFile(path(kFileImage, cam), EncodePng(view.rgb, options.png));
    WriteFile(path(kFileMask, cam), EncodePng(view.hand_mask, options.png));
    if (options.scene.objects) {
      WriteFile(path(kFileObjectMask, cam), EncodePng(view.object_mask, options.png));
    }
    if (options.write_depth) {
      WritePng16(path(kFileDepth, cam), DepthToU16(view.depth, manifest.depth_unit_m),
                 options.png);
    }
    ViewKeypoints kp;
    kp.camera = cam;
    kp.keypoints.uv_px = view.keypoints;
    kp.visibility = view.visibility;
    kp.keypoints.confidence.setOnes();
    kp.status = view.status;
    kp.hand_pixels = view.hand_pixels;
    gt2d.push_back(kp);
    status_counts[view.status == "visible" ? 0 : view.status == "occluded" ? 1 : 2]++;
    if (options.write_detections) {
      const ViewDetections& det = frame.detections[c];
      WriteFile(path(kFileDetectionMask, cam), EncodePng(det.mask, options.png));
      ViewKeypoints d;
      d.camera = cam;
      d.keypoints = det.keypoints;
      d.visibility.fill(-1);
      det2d.push_back(d);
    }
  }
  WriteFile(path(kFileKeypoints, ""), ViewKeypointsToJson(id, gt2d, true).dump() + "\n");
  if (options.write_detections) {
    WriteFile(path(kFileDetections, ""),
              ViewKeypointsToJson(id, det2d, false).dump() + "\n");
  }
  HandGroundTruth gt;
  gt.hand_model = model.name;
  gt.side = manifest.hand_side;
  gt.pose_kind = frame.scene.pose_kind;
  gt.params = frame.scene.params;
  gt.keypoints = frame.scene.hand.keypoints;
  gt.joints = frame.scene.hand.joints;
  gt.vertices = frame.scene.hand.vertices;
  for (const SynthObject& o : frame.scene.objects) {
    gt.objects.push_back({o.kind, o.size, o.world_from_object});
  }
  WriteFile(path(kFileGroundTruth, ""), GroundTruthToJson(id, gt).dump() + "\n");
  return status_counts;
}

}  // namespace

SynthCaptureSummary WriteSynthCapture(const HandModel& model,
                                      const SynthCaptureOptions& options,
                                      const std::string& out_dir,
                                      const std::string& hand_model_source,
                                      bool overwrite,
                                      const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  options.Check("synth options");
  PrepareOutputFolder(out_dir, overwrite);
  const fs::path root(out_dir);
  const SynthGenerator generator(model, MakePresetRig(options.rig, options.seed),
                                 options);
  const Rig& rig = generator.rig();
  const CaptureManifest manifest = MakeManifest(model, options, rig, hand_model_source);
  WriteCaptureFolders(root, manifest, rig);

  std::atomic<int> done{0};
  std::mutex progress_mutex;
  std::vector<std::array<int, 3>> status_counts(options.num_frames);
  auto write_frame = [&](int f) {
    status_counts[f] = WriteFrameFiles(generator, manifest, root, options, model, f);
    const int n = ++done;
    if (progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(n, options.num_frames);
    }
  };
  auto run = [&] { tbb::parallel_for(0, options.num_frames, write_frame); };
  if (options.num_threads > 0) {
    tbb::task_arena arena(options.num_threads);
    arena.execute(run);
  } else {
    run();
  }

  // Written atomically and last: its presence marks the capture complete.
  WriteFileAtomically((root / kCaptureManifestFile).string(),
                      ManifestToJson(manifest).dump(2) + "\n");
  SynthCaptureSummary summary;
  summary.frames = options.num_frames;
  summary.views = options.num_frames * static_cast<int>(rig.size());
  for (const auto& s : status_counts) {
    summary.views_visible += s[0];
    summary.views_occluded += s[1];
    summary.views_out_of_frame += s[2];
  }
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace handlabel
