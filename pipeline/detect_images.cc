#include "pipeline/detect_images.h"

#include <chrono>
#include <filesystem>
#include <mutex>

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/json_util.h"
#include "image/image_file.h"

namespace handlabel {
namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
      .count();
}

nlohmann::json PalmJson(const PalmDetection& p) {
  nlohmann::json kps = nlohmann::json::array();
  for (const auto& k : p.keypoints) kps.push_back({k.x(), k.y()});
  return {
      {"score", p.score},
      {"box",
       {{"xmin", p.xmin}, {"ymin", p.ymin}, {"width", p.width}, {"height", p.height}}},
      {"keypoints", kps}};
}

nlohmann::json RectJson(const NormalizedRect& r) {
  return {{"x_center", r.x_center},
          {"y_center", r.y_center},
          {"width", r.width},
          {"height", r.height},
          {"rotation", r.rotation}};
}

nlohmann::json HandJson(const HandDetection& d) {
  const HandLandmarks& h = d.hand;
  nlohmann::json norm = nlohmann::json::array(), px = nlohmann::json::array(),
                 crop = nlohmann::json::array(), world = nlohmann::json::array();
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    norm.push_back({h.normalized[k].x(), h.normalized[k].y(), h.normalized[k].z()});
    px.push_back({h.image_px(k, 0), h.image_px(k, 1)});
    crop.push_back({h.crop_px(k, 0), h.crop_px(k, 1)});
    world.push_back({h.world_m[k].x(), h.world_m[k].y(), h.world_m[k].z()});
  }
  const bool left_label = h.left_in_mirror_score >= 0.5;
  return {{"roi", RectJson(h.roi)},
          {"landmarks_norm", norm},
          {"landmarks_px", px},
          {"landmarks_crop_px", crop},
          {"world_landmarks_m", world},
          {"confidence", JsonArray(d.keypoints.confidence)},
          {"presence", h.presence},
          {"handedness",
           {{"label", left_label ? "Left" : "Right"},
            {"score", h.side_score()},
            {"side", HandSideName(h.side())}}}};
}

// Whether `path` is a record DetectionRecordJson wrote (an object with its keys).
bool IsDetectionRecord(const std::filesystem::path& path) {
  try {
    const nlohmann::json j = ReadJsonFileStrict(path.string());
    return j.is_object() && j.contains("image") && j.contains("palms") &&
           j.contains("hands") && j.contains("time_ms");
  } catch (const std::exception&) {
    return false;
  }
}

// Removes <out_dir>/<n>.json for n >= `count` that an earlier run wrote (a detection
// record by its content): the folder then holds this run's results only. Any other
// file, a user's own included, stays.
int RemoveEarlierRecords(const std::string& out_dir, size_t count) {
  int removed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out_dir)) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() != ".json" || stem.empty() || stem.size() > 9 ||
        stem.find_first_not_of("0123456789") != std::string::npos ||
        std::stoul(stem) < count || !IsDetectionRecord(entry.path())) {
      continue;
    }
    std::filesystem::remove(entry.path());
    ++removed;
  }
  return removed;
}

}  // namespace

ImageU8 ToRgb(const ImageU8& image) {
  if (image.channels == 3) return image;
  ImageU8 rgb(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        rgb.at(x, y, c) = image.at(x, y, image.channels >= 3 ? c : 0);
      }
    }
  }
  return rgb;
}

nlohmann::json DetectionRecordJson(const std::string& image_path, const ImageU8& rgb,
                                   const MediapipeTrace& trace,
                                   const std::vector<HandDetection>& hands,
                                   double read_ms) {
  nlohmann::json palms = nlohmann::json::array(), out_hands = nlohmann::json::array();
  for (const auto& p : trace.palms) palms.push_back(PalmJson(p));
  for (const auto& h : hands) out_hands.push_back(HandJson(h));
  return {
      {"image", image_path},
      {"width", rgb.width},
      {"height", rgb.height},
      {"palms", palms},
      {"hands", out_hands},
      {"time_ms",
       {{"read", read_ms}, {"palm", trace.palm_ms}, {"landmarks", trace.landmarks_ms}}}};
}

int DetectImages(const MediapipeHands& detector, const std::vector<std::string>& images,
                 const std::string& out_dir, int threads,
                 const std::function<void(int, int)>& on_image) {
  std::filesystem::create_directories(out_dir);
  // One writer per folder: a second run into it would mix its records with this
  // run's, and each removes the other's beyond its own image count.
  const FileLock writer = LockFolderForWriting(out_dir, "detect --images", "--out", "");
  nlohmann::json summary = {{"detector", "handlabel MediapipeHands"},
                            {"model", detector.options().model},
                            {"max_hands", detector.options().max_hands}};
  // Images in parallel (each on the detector's own thread count); the records and the
  // summary are in the images' order whatever the count.
  const int total = static_cast<int>(images.size());
  std::vector<nlohmann::json> per_image(images.size());
  std::vector<MediapipeTrace> traces(images.size());
  std::mutex mutex;  // on_image
  int done = 0;
  tbb::task_arena arena(threads > 0 ? threads : tbb::info::default_concurrency());
  arena.execute([&] {
    tbb::parallel_for(0, total, [&](int i) {
      const auto t0 = std::chrono::steady_clock::now();
      const ImageU8 rgb = ToRgb(ReadImageFile(images[i]));
      const double read_ms = MsSince(t0);
      const auto hands = detector.Detect(rgb, &traces[i]);
      const nlohmann::json record =
          DetectionRecordJson(images[i], rgb, traces[i], hands, read_ms);
      WriteFileAtomically(out_dir + "/" + std::to_string(i) + ".json",
                          record.dump(1) + "\n");
      per_image[i] = {{"image", images[i]},
                      {"hands", hands.size()},
                      {"palm_ms", traces[i].palm_ms},
                      {"landmarks_ms", traces[i].landmarks_ms}};
      const std::lock_guard<std::mutex> lock(mutex);
      if (on_image) on_image(++done, total);
    });
  });
  double palm_sum = 0, landmark_sum = 0;
  for (const MediapipeTrace& trace : traces) {
    palm_sum += trace.palm_ms;
    landmark_sum += trace.landmarks_ms;
  }
  const double n = std::max<size_t>(images.size(), 1);
  summary["images"] = per_image;
  summary["mean_palm_ms"] = palm_sum / n;
  summary["mean_landmarks_ms"] = landmark_sum / n;
  const int removed = RemoveEarlierRecords(out_dir, images.size());
  WriteFileAtomically(out_dir + "/summary.json", summary.dump(1) + "\n");
  return removed;
}

}  // namespace handlabel
