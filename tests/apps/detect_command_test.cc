#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/capture_reader.h"
#include "core/data_dir.h"
#include "image/image_file.h"
#include "network/detector/detector_overlay.h"
#include "pipeline/job_config.h"
#include "pipeline/label_stage_factory.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

bool ModelsPresent() {
  return std::filesystem::exists(
             ShippedModelPath("mediapipe/palm_detection_full.tflite")) &&
         std::filesystem::exists(ShippedModelPath("mediapipe/hand_landmark_full.tflite"));
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(DetectCommand, UsageErrors) {
  EXPECT_EQ(RunHandlabelCommand({"detect"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"detect", "--images", "a.png"}).status, 2);  // no --out
  EXPECT_EQ(
      RunHandlabelCommand({"detect", "--capture", "c", "--images", "a.png", "--out", "o"})
          .status,
      2);
  // A flag of the other mode is refused, named, not ignored.
  const testing::CommandResult video_on_images =
      RunHandlabelCommand({"detect", "--images", "a.png", "--out", "o", "--video"});
  EXPECT_EQ(video_on_images.status, 2);
  EXPECT_NE(video_on_images.err.find("--video works with --capture only"),
            std::string::npos)
      << video_on_images.err;
  EXPECT_EQ(RunHandlabelCommand({"detect", "--capture", "c", "--out", "o"}).status, 2);
  const testing::CommandResult palm_every =
      RunHandlabelCommand({"detect", "--capture", "c", "--palm-every", "5"});
  EXPECT_EQ(palm_every.status, 2);
  EXPECT_NE(palm_every.err.find("--palm-every needs --video"), std::string::npos);
  EXPECT_EQ(
      RunHandlabelCommand({"detect", "--capture", "c", "--video", "--palm-every", "-1"})
          .status,
      2);
  const testing::CommandResult bad = RunHandlabelCommand(
      {"detect", "--images", "a.png", "--out", testing::ScratchDir(), "--model", "huge"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("full or lite"), std::string::npos) << bad.err;
}

TEST(DetectCommand, KeepsExistingDetectionsUnlessOverwriteIsGiven) {
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "random", "--cameras", "2",
                                 "--size", "64x48", "--frames", "1", "--hand-model",
                                 "capsule", "--out", dir + "/cap"})
                .status,
            0);
  const std::string before = ReadJson(dir + "/cap/detections/000000.json").dump();
  const testing::CommandResult r =
      RunHandlabelCommand({"detect", "--capture", dir + "/cap"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("files.detections"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(ReadJson(dir + "/cap/detections/000000.json").dump(), before);
}

// The multi-view detector on a rendered DexYCB-like frame (seed 7: MediaPipe's palm
// detector fires in 2 of its 8 views): the views agree on the hand, the others are found
// from it, detections lie near the true keypoints, views without one say why.
// `detect --images` into a folder of an earlier run with more images (issue 46: its
// <n>.json beyond this run stayed beside the new ones): they are removed, with a note;
// a file of the user's, even one named like a record, stays.
TEST(DetectCommand, ImagesIntoAFolderOfEarlierResultsKeepsOnlyThisRunsRecords) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  const std::string dir = testing::ScratchDir();
  std::vector<std::string> images;
  for (int i = 0; i < 3; ++i) {
    ImageU8 image(64, 48, 3, static_cast<uint8_t>(40 * i));
    images.push_back(dir + "/" + std::to_string(i) + ".png");
    WritePng(images.back(), image);
  }
  const std::string out = dir + "/det";
  std::vector<std::string> args = {"detect", "--images"};
  args.insert(args.end(), images.begin(), images.end());
  args.insert(args.end(), {"--out", out});
  ASSERT_EQ(RunHandlabelCommand(args).status, 0);
  std::filesystem::create_directories(out);
  std::ofstream(out + "/7.json") << "{\"mine\": true}\n";
  std::ofstream(out + "/notes.txt") << "kept\n";
  const testing::CommandResult again =
      RunHandlabelCommand({"detect", "--images", images[0], "--out", out});
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find("removed 2 records of an earlier run with more images"),
            std::string::npos)
      << again.err;
  EXPECT_TRUE(std::filesystem::exists(out + "/0.json"));
  EXPECT_FALSE(std::filesystem::exists(out + "/1.json"));
  EXPECT_FALSE(std::filesystem::exists(out + "/2.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/7.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/notes.txt"));
  EXPECT_EQ(ReadJson(out + "/summary.json")["images"].size(), 1u);
}

TEST(DetectCommand, CaptureViewsGetDetectionsOrReasons) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "1", "--seed",
                                 "3", "--out", dir + "/cap"})
                .status,
            0);
  const testing::CommandResult r =
      RunHandlabelCommand({"detect", "--capture", dir + "/cap", "--overwrite"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CaptureReader capture(dir + "/cap");
  const auto truth = capture.ReadKeypoints(0);
  const nlohmann::json det = ReadJson(dir + "/cap/detections/000000.json");
  ASSERT_EQ(det["views"].size(), static_cast<size_t>(capture.num_cameras()));
  const auto views = capture.ReadDetections(0);  // the native reader accepts the file
  EXPECT_TRUE(det["hand"]["found"].get<bool>());
  EXPECT_EQ(det["hand"]["side"], "right");  // synth renders right hands
  int detected = 0;
  for (int c = 0; c < capture.num_cameras(); ++c) {
    detected += det["views"][c]["detected"].get<bool>() ? 1 : 0;
  }
  EXPECT_GE(detected, 6);
  for (int c = 0; c < capture.num_cameras(); ++c) {
    const nlohmann::json& v = det["views"][c];
    if (!v["detected"].get<bool>()) {
      EXPECT_FALSE(v["reason"].get<std::string>().empty());
      continue;
    }
    // Median distance to the true keypoints visible in the view.
    std::vector<double> errors;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (views[c].keypoints.confidence(k) <= 0 || truth[c].visibility[k] != 2) continue;
      errors.push_back(
          (views[c].keypoints.uv_px.row(k) - truth[c].keypoints.uv_px.row(k)).norm());
    }
    if (errors.empty()) continue;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    EXPECT_LT(errors[errors.size() / 2], 25.0) << "camera " << c;
  }
}

// A job file for the capture in `capture` whose 2D is `keypoints_2d` (fit-only).
void WriteFitOnlyJob(const std::string& path, const std::string& capture,
                     const std::string& keypoints_2d, const std::string& out,
                     const std::string& more_sections = "") {
  std::ofstream(path) << "name: t\nseed: 3\ninput:\n  format: native\n  path: " << capture
                      << "\nnetwork:\n  weights: \"\"\nrefine:\n  mode: always\n"
                      << "evidence:\n  keypoints_2d: " << keypoints_2d
                      << "\n  masks: none\noutput:\n  dir: " << out
                      << "\n  meshes: []\n  overlays: true\n  overlay_format: png"
                      << "\n  evaluate: true\n"
                      << more_sections;
}

// `evidence.keypoints_2d: detector` runs the detector inside the job: its 2D is what
// `handlabel detect` + `keypoints_2d: files` gives, bit for bit, so the labels agree too;
// its overlays show the detections.
TEST(DetectCommand, LabelJobWithDetectorGivesTheSame2dAsDetectThenFiles) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  namespace fs = std::filesystem;
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "1", "--seed",
                                 "3", "--no-detections", "--out", dir + "/cap"})
                .status,
            0);
  fs::copy(dir + "/cap", dir + "/detected", fs::copy_options::recursive);
  ASSERT_EQ(RunHandlabelCommand({"detect", "--capture", dir + "/detected"}).status, 0);
  WriteFitOnlyJob(dir + "/detector.yaml", dir + "/cap", "detector", dir + "/labels_a");
  WriteFitOnlyJob(dir + "/files.yaml", dir + "/detected", "files", dir + "/labels_b");

  const auto in_job = BuildFrameSource(LoadJobConfig(dir + "/detector.yaml"));
  const auto from_files = BuildFrameSource(LoadJobConfig(dir + "/files.yaml"));
  EXPECT_NE(in_job->KeypointsSource().find("detector"), std::string::npos);
  const FrameInput a = in_job->Load("000000"), b = from_files->Load("000000");
  ASSERT_EQ(a.keypoints_2d.size(), b.keypoints_2d.size());
  int known = 0;
  for (size_t c = 0; c < a.keypoints_2d.size(); ++c) {
    ASSERT_TRUE(a.keypoints_2d[c] && b.keypoints_2d[c]) << "camera " << c;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      EXPECT_EQ(a.keypoints_2d[c]->confidence(k), b.keypoints_2d[c]->confidence(k));
      EXPECT_EQ(a.keypoints_2d[c]->uv_px(k, 0), b.keypoints_2d[c]->uv_px(k, 0));
      EXPECT_EQ(a.keypoints_2d[c]->uv_px(k, 1), b.keypoints_2d[c]->uv_px(k, 1));
      known += a.keypoints_2d[c]->confidence(k) > 0;
    }
  }
  EXPECT_GE(known, 6 * kNumHandKeypoints / 2);  // the hand was found in several views

  const testing::CommandResult ra =
      RunHandlabelCommand({"label", "--job", dir + "/detector.yaml"});
  ASSERT_EQ(ra.status, 0) << ra.err;
  const testing::CommandResult rb =
      RunHandlabelCommand({"label", "--job", dir + "/files.yaml"});
  ASSERT_EQ(rb.status, 0) << rb.err;
  const nlohmann::json la = ReadJson(dir + "/labels_a/labels/000000.json");
  const nlohmann::json lb = ReadJson(dir + "/labels_b/labels/000000.json");
  EXPECT_EQ(la["mano"].dump(), lb["mano"].dump());
  EXPECT_EQ(la["keypoints_3d"].dump(), lb["keypoints_3d"].dump());
  // The detector job's overlays carry the detections: the palm-box or ROI colours.
  const ImageU8 overlay = ReadImageFile(dir + "/labels_a/overlays/000000/cam00.png");
  const ImageU8 plain = ReadImageFile(dir + "/labels_b/overlays/000000/cam00.png");
  int roi_pixels = 0, plain_roi_pixels = 0;
  for (size_t p = 0; p + 2 < overlay.data.size(); p += 3) {
    const Rgb a_px = {overlay.data[p], overlay.data[p + 1], overlay.data[p + 2]};
    const Rgb b_px = {plain.data[p], plain.data[p + 1], plain.data[p + 2]};
    roi_pixels += a_px == kRoiColor || a_px == kNoHandColor;
    plain_roi_pixels += b_px == kRoiColor || b_px == kNoHandColor;
  }
  EXPECT_GT(roi_pixels, 100);
  EXPECT_EQ(plain_roi_pixels, 0);
}

// Frames detected at once (`detect --threads 2`, and a detector job's frames on two
// threads) give what one at a time gives, bit for bit: each frame's detection depends
// on its own images only, whichever thread runs it.
// Expects the two captures' detection files equal byte for byte, and the two label
// folders' labels equal (keypoints and parameters) for every frame; returns the frames.
// `subfolder`: labels/ (the per-frame labels) or smoothed/labels/.
int CompareDetectionsAndLabels(const std::string& capture_a, const std::string& capture_b,
                               const std::string& labels_a, const std::string& labels_b,
                               const std::string& subfolder = "labels") {
  namespace fs = std::filesystem;
  int frames = 0;
  for (const auto& entry : fs::directory_iterator(capture_a + "/detections")) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(testing::ReadFileBytes(entry.path().string()),
              testing::ReadFileBytes(capture_b + "/detections/" + name))
        << name;
    const std::string stem = entry.path().stem().string();
    const nlohmann::json a = ReadJson(labels_a + "/" + subfolder + "/" + stem + ".json");
    const nlohmann::json b = ReadJson(labels_b + "/" + subfolder + "/" + stem + ".json");
    EXPECT_EQ(a["keypoints_3d"].dump(), b["keypoints_3d"].dump()) << stem;
    EXPECT_EQ(a["mano"].dump(), b["mano"].dump()) << stem;
    ++frames;
  }
  return frames;
}

TEST(DetectCommand, FramesInParallelGiveTheSameDetectionsAndLabels) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  namespace fs = std::filesystem;
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "3", "--seed",
                                 "5", "--no-detections", "--out", dir + "/cap"})
                .status,
            0);
  for (const std::string threads : {"1", "2"}) {
    const std::string capture = dir + "/cap" + threads;
    fs::copy(dir + "/cap", capture, fs::copy_options::recursive);
    const testing::CommandResult r =
        RunHandlabelCommand({"detect", "--capture", capture, "--threads", threads});
    ASSERT_EQ(r.status, 0) << r.err;
    std::ofstream(dir + "/job" + threads + ".yaml")
        << "name: t\nseed: 3\ninput: {format: native, path: " << dir
        << "/cap}\nnetwork: {weights: \"\", threads: " << threads
        << "}\nrefine: {mode: always}\nevidence: {keypoints_2d: detector, masks: none}\n"
        << "output: {dir: " << dir << "/labels" << threads
        << ", meshes: [], overlays: false}\n";
    const testing::CommandResult job =
        RunHandlabelCommand({"label", "--job", dir + "/job" + threads + ".yaml"});
    ASSERT_EQ(job.status, 0) << job.err;
  }
  EXPECT_EQ(CompareDetectionsAndLabels(dir + "/cap1", dir + "/cap2", dir + "/labels1",
                                       dir + "/labels2"),
            3);
  // The job keeps its detector's answers: the files `detect` writes.
  EXPECT_EQ(CompareDetectionsAndLabels(dir + "/cap1", dir + "/labels2", dir + "/labels1",
                                       dir + "/labels2"),
            3);
}

// The keypoints of every view of a detections record (NaN where unknown), as text.
std::string ViewKeypointsText(const nlohmann::json& detections) {
  std::string out;
  for (const nlohmann::json& view : detections["views"]) out += view["keypoints"].dump();
  return out;
}

// Video mode on a synthetic sequence (one motion, realistic look): after the first
// frame the regions come from the previous frame's 3D hand; it finds the hand in at
// least as many views as detecting every frame from scratch, on the hand (truth), and
// its first frame is the per-frame detection.
TEST(DetectCommand, VideoModeTracksTheHandThroughASequence) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  namespace fs = std::filesystem;
  const std::string dir = testing::ScratchDir();
  const int frames = 6;
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--sequence", "--frames",
                                 std::to_string(frames), "--seed", "45", "--appearance",
                                 "realistic", "--no-detections", "--out", dir + "/cap"})
                .status,
            0);
  fs::copy(dir + "/cap", dir + "/video", fs::copy_options::recursive);
  ASSERT_EQ(RunHandlabelCommand({"detect", "--capture", dir + "/cap"}).status, 0);
  const testing::CommandResult r = RunHandlabelCommand(
      {"detect", "--capture", dir + "/video", "--video", "--palm-every", "0"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("tracked from the previous frame"), std::string::npos) << r.out;

  const CaptureReader capture(dir + "/video");
  int per_frame_views = 0, video_views = 0, tracked_frames = 0, tracked_views = 0;
  std::vector<double> errors;
  for (int f = 0; f < frames; ++f) {
    const std::string id = capture.frame_id(f);
    const nlohmann::json one = ReadJson(dir + "/cap/detections/" + id + ".json");
    const nlohmann::json video = ReadJson(dir + "/video/detections/" + id + ".json");
    EXPECT_FALSE(one.contains("tracking"));  // per-frame records are as before
    const std::string tracking = video["tracking"];
    // --palm-every 0: only the first frame starts a run.
    if (f == 0) {
      EXPECT_EQ(tracking, "start");
      EXPECT_EQ(ViewKeypointsText(video), ViewKeypointsText(one));
    } else {
      EXPECT_NE(tracking, "start") << id;
    }
    tracked_frames += tracking == "track";
    const auto truth = capture.ReadKeypoints(f);
    const auto views = capture.ReadDetections(f);
    for (int c = 0; c < capture.num_cameras(); ++c) {
      const nlohmann::json& v = video["views"][c];
      per_frame_views += one["views"][c]["detected"].get<bool>();
      video_views += v["detected"].get<bool>();
      if (tracking == "track") {
        EXPECT_TRUE(v["region"] == "track" || v["region"] == "palm" ||
                    v["region"] == "outside")
            << v["region"];
        // Palm detection runs only where the track did not hold.
        if (v["region"] != "palm") {
          EXPECT_EQ(v["palm_candidates"], 0);
        }
      } else {
        EXPECT_EQ(v["region"], "palm");
      }
      if (!v["detected"].get<bool>()) continue;
      tracked_views += v["source"] == "track";
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (views[c].keypoints.confidence(k) <= 0 || truth[c].visibility[k] != 2)
          continue;
        errors.push_back(
            (views[c].keypoints.uv_px.row(k) - truth[c].keypoints.uv_px.row(k)).norm());
      }
    }
  }
  EXPECT_GE(tracked_frames, frames - 2);
  EXPECT_GE(tracked_views, 3 * tracked_frames);
  EXPECT_GE(video_views, per_frame_views);
  ASSERT_FALSE(errors.empty());
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 10.0);
}

// Video mode gives the same files at any thread count (runs in parallel, a run's frames
// in order), and a label job in video mode the 2D and labels of `detect --video` +
// `keypoints_2d: files`, bit for bit, on two threads against one.
TEST(DetectCommand, VideoModeIsTheSameAtAnyThreadCountAndInAJob) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  namespace fs = std::filesystem;
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--sequence", "--frames",
                                 "5", "--seed", "46", "--appearance", "realistic",
                                 "--no-detections", "--out", dir + "/cap"})
                .status,
            0);
  for (const std::string threads : {"1", "2"}) {
    fs::copy(dir + "/cap", dir + "/cap" + threads, fs::copy_options::recursive);
    const testing::CommandResult r =
        RunHandlabelCommand({"detect", "--capture", dir + "/cap" + threads, "--video",
                             "--palm-every", "3", "--threads", threads});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  // Both jobs smooth (sequence): the detector job from the answers it kept.
  const std::string smooth = "sequence: {smooth: true, window: 4, overlap: 2}\n";
  WriteFitOnlyJob(dir + "/files.yaml", dir + "/cap1", "files", dir + "/labels_files",
                  smooth);
  std::ofstream(dir + "/video.yaml")
      << "name: t\nseed: 3\ninput: {format: native, path: " << dir
      << "/cap}\nnetwork: {weights: \"\", threads: 2}\nrefine: {mode: always}\n"
      << "evidence: {keypoints_2d: detector, detector_mode: video, "
      << "detector_palm_every: 3, masks: none}\n"
      << "output: {dir: " << dir << "/labels_video, meshes: [], overlays: false}\n"
      << smooth;
  for (const std::string job : {"files", "video"}) {
    const testing::CommandResult r =
        RunHandlabelCommand({"label", "--job", dir + "/" + job + ".yaml"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_EQ(CompareDetectionsAndLabels(dir + "/cap1", dir + "/cap2",
                                       dir + "/labels_files", dir + "/labels_video"),
            5);
  EXPECT_EQ(CompareDetectionsAndLabels(dir + "/cap1", dir + "/labels_video",
                                       dir + "/labels_files", dir + "/labels_video",
                                       "smoothed/labels"),
            5);
  // Frames 0 and 3 start runs; the others follow the previous frame.
  EXPECT_EQ(ReadJson(dir + "/cap1/detections/000003.json")["tracking"], "start");
}

}  // namespace
}  // namespace handlabel
