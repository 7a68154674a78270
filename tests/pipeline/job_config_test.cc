#include "pipeline/job_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "pipeline/label_job.h"
#include "pipeline/label_stage_factory.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string WriteJob(const std::string& yaml) {
  const fs::path path = fs::path(testing::ScratchDir()) / "job.yaml";
  std::ofstream(path) << yaml;
  return path.string();
}

const char* kValidJob = R"(
name: demo
seed: 7
input: {format: native, path: capture, frames: "0:10"}
network: {weights: weights.pt, batch_size: 2}
refine: {mode: always, max_reprojection_px: 9.5}
output: {dir: labels, meshes: [ply, obj], overlays: false}
)";

TEST(JobConfig, ReadsFieldsAndResolvesPathsAgainstTheJobFolder) {
  const std::string path = WriteJob(kValidJob);
  const JobConfig job = LoadJobConfig(path);
  const fs::path dir = fs::path(path).parent_path();
  EXPECT_EQ(job.name, "demo");
  EXPECT_EQ(job.seed, 7u);
  EXPECT_EQ(job.frames, "0:10");
  EXPECT_EQ(job.input_path, (dir / "capture").string());
  EXPECT_EQ(job.network_weights, (dir / "weights.pt").string());
  EXPECT_EQ(job.batch_size, 2);
  EXPECT_EQ(job.refine_mode, RefineMode::kAlways);
  EXPECT_DOUBLE_EQ(job.quality.max_reprojection_px, 9.5);
  EXPECT_EQ(job.meshes, (std::vector<std::string>{"ply", "obj"}));
  EXPECT_FALSE(job.overlays);
  EXPECT_TRUE(job.evaluate);  // default
  EXPECT_EQ(job.masks, MaskSource::kFiles);
  // Default: the network's own keypoints are the only evidence -> its masks count.
  EXPECT_EQ(job.keypoints, KeypointSource::kNetwork);
  EXPECT_DOUBLE_EQ(job.network_mask_sigma_px, 2.0);
  EXPECT_EQ(job.network_keypoints, AnswerKeypoints::kMean);  // default
  const JobConfig joints = LoadJobConfig(WriteJob(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w, keypoints: joints}\n"));
  EXPECT_EQ(joints.network_keypoints, AnswerKeypoints::kJoints);
  EXPECT_EQ(job.network_precision, "fp32");  // default: the same labels on every CPU
  const JobConfig bf16 = LoadJobConfig(WriteJob(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w, precision: auto}\n"));
  EXPECT_EQ(bf16.network_precision, "auto");
  const JobConfig with_files = LoadJobConfig(
      WriteJob(std::string(kValidJob) + "evidence: {keypoints_2d: both}\n"));
  EXPECT_DOUBLE_EQ(with_files.network_mask_sigma_px, 16.0);
  const JobConfig with_masks =
      LoadJobConfig(WriteJob(std::string(kValidJob) +
                             "evidence: {masks: network, network_mask_sigma_px: 6.5}\n"));
  EXPECT_EQ(with_masks.masks, MaskSource::kNetwork);
  EXPECT_DOUBLE_EQ(with_masks.network_mask_sigma_px, 6.5);
}

void ExpectError(const std::string& yaml, const std::string& field,
                 const std::string& expected) {
  try {
    LoadJobConfig(WriteJob(yaml));
    ADD_FAILURE() << "no error for:\n" << yaml;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("job.yaml"));
    EXPECT_THAT(e.what(), HasSubstr("'" + field + "'"));
    EXPECT_THAT(e.what(), HasSubstr(expected));
  }
}

TEST(JobConfig, ErrorsNameTheFieldAndWhatWasExpected) {
  const std::string base = "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n";
  ExpectError(base + "refine: {mode: sometimes}\n", "refine.mode",
              "off | always | fallback");
  ExpectError(base + "refine: {mode: always, max_reprojection_px: abc}\n",
              "refine.max_reprojection_px", "a number");
  ExpectError(base + "outptu: {dir: x}\n", "outptu", "a known key");
  ExpectError(base + "refine: {mode: always, tolerance: 3}\n", "refine.tolerance",
              "a known key");
  ExpectError("input: {path: c}\nnetwork: {weights: w}\n", "output.dir",
              "an output folder");
  ExpectError(
      "input: {path: c, format: kinect}\noutput: {dir: o}\nnetwork: {weights: w}\n",
      "input.format", "native | dexycb");
  ExpectError("input: {path: c}\noutput: {dir: o}\n", "refine.mode", "'always' when");
  ExpectError(
      "input: {path: c}\noutput: {dir: o, meshes: [stl]}\nnetwork: {weights: w}\n",
      "output.meshes", "ply and/or obj");
  ExpectError(
      "input: {path: c}\noutput: {dir: o, overlay_format: gif}\nnetwork: {weights: w}\n",
      "output.overlay_format", "jpg or png");
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w, keypoints: tips}\n",
      "network.keypoints", "joints | mesh | mean");
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w, precision: fp16}\n",
      "network.precision", "fp32, bf16 or auto");
  ExpectError(base + "refine: {mode: always}\nevidence: {network_mask_sigma_px: -1}\n",
              "evidence.network_mask_sigma_px", "> 0 pixels");
}

// Section sequence: read, defaults without it, and errors naming the field.
TEST(JobConfig, SequenceSection) {
  const std::string base =
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: files}\n";
  const JobConfig plain = LoadJobConfig(WriteJob(base));
  EXPECT_FALSE(plain.sequence.smooth);
  EXPECT_EQ(plain.sequence.window, 48);
  const JobConfig job = LoadJobConfig(
      WriteJob(base +
               "sequence: {smooth: true, window: 32, overlap: 8, acceleration_sigma_mm: "
               "0.5, iterations: 20}\n"));
  EXPECT_TRUE(job.sequence.smooth);
  EXPECT_EQ(job.sequence.window, 32);
  EXPECT_EQ(job.sequence.overlap, 8);
  EXPECT_DOUBLE_EQ(job.sequence.acceleration_sigma_mm, 0.5);
  EXPECT_EQ(job.sequence.iterations, 20);
  EXPECT_EQ(plain.sequence.detector_keypoints, "none");
  EXPECT_EQ(LoadJobConfig(WriteJob(base + "sequence: {detector_keypoints: mediapipe}\n"))
                .sequence.detector_keypoints,
            "mediapipe");
  ExpectError(base + "sequence: {detector_keypoints: \"\"}\n",
              "sequence.detector_keypoints", "none, mediapipe or");
  ExpectError(base + "sequence: {window: 32, overlap: 20}\n", "sequence.overlap",
              "at most half of sequence.window");
  ExpectError(base + "sequence: {window: 2, overlap: 1}\n", "sequence.window", "3");
  ExpectError(base + "sequence: {acceleration_sigma_mm: 0}\n",
              "sequence.acceleration_sigma_mm", "0");
  ExpectError(base + "sequence: {smoth: true}\n", "sequence.smoth", "a known key");
  // Smoothing refits 2D kept on disk: refused on loading for the network's own 2D and
  // for a detector that skips frames; the detector on every frame keeps its answers.
  const std::string other = "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n";
  const std::string smooth = "sequence: {smooth: true}\n";
  ExpectError(other + smooth, "evidence.keypoints_2d", "network");
  ExpectError(other + "evidence: {keypoints_2d: detector, detector_every: 10}\n" + smooth,
              "evidence.keypoints_2d", "detector with detector_every 10");
  EXPECT_TRUE(
      LoadJobConfig(WriteJob(other + "evidence: {keypoints_2d: detector}\n" + smooth))
          .sequence.smooth);
  // The section does not enter the job hash: per-frame labels stay where they were.
  EXPECT_EQ(JobHash(plain, ""), JobHash(job, ""));
}

// fit.detector_keypoints: unset keeps the fit's defaults (and the job hash); set, it
// enters the hash (the labels change) and the fitter gets the detector's model.
TEST(JobConfig, FitDetectorKeypoints) {
  const std::string base =
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: files}\n";
  const JobConfig plain = LoadJobConfig(WriteJob(base));
  EXPECT_FALSE(plain.fit.detector_keypoints);
  EXPECT_TRUE(plain.fit.IsDefault());
  EXPECT_EQ(FitterOptions(plain).fit.detector_keypoints, nullptr);
  const JobConfig none =
      LoadJobConfig(WriteJob(base + "fit: {detector_keypoints: none}\n"));
  EXPECT_EQ(FitterOptions(none).fit.detector_keypoints, nullptr);
  const JobConfig mediapipe =
      LoadJobConfig(WriteJob(base + "fit: {detector_keypoints: mediapipe}\n"));
  EXPECT_NE(JobHash(mediapipe, ""), JobHash(plain, ""));
  EXPECT_NE(JobHash(mediapipe, ""), JobHash(none, ""));
  const auto model = FitterOptions(mediapipe).fit.detector_keypoints;
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->detector, "mediapipe");
  ExpectError(base + "fit: {detector_keypoints: \"\"}\n", "fit.detector_keypoints",
              "none, mediapipe or");
  const JobConfig missing =
      LoadJobConfig(WriteJob(base + "fit: {detector_keypoints: no_such_model.json}\n"));
  try {
    FitterOptions(missing);
    ADD_FAILURE() << "a missing model file must be refused";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("fit.detector_keypoints"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("no_such_model.json"));
  }
}

// evidence.keypoints_2d: detector: the detector's 2D counts as file evidence, with the
// model size; it cannot be combined with a detections folder.
TEST(JobConfig, KeypointsFromTheDetector) {
  const std::string base = "input: {path: c}\noutput: {dir: o}\nrefine: {mode: always}\n";
  const JobConfig plain =
      LoadJobConfig(WriteJob(base + "evidence: {keypoints_2d: files}\n"));
  EXPECT_FALSE(plain.keypoints_from_detector);
  const JobConfig job = LoadJobConfig(
      WriteJob(base + "evidence: {keypoints_2d: detector, detector_model: lite}\n"));
  EXPECT_TRUE(job.keypoints_from_detector);
  EXPECT_EQ(job.keypoints, KeypointSource::kFiles);
  EXPECT_EQ(job.detector_model, "lite");
  EXPECT_EQ(LoadJobConfig(WriteJob(base + "evidence: {keypoints_2d: detector}\n"))
                .detector_model,
            "full");
  ExpectError(base + "evidence: {keypoints_2d: detector, detector_model: huge}\n",
              "evidence.detector_model", "full | lite");
  ExpectError(base + "evidence: {keypoints_2d: detector, detections: d}\n",
              "evidence.detections", "empty with keypoints_2d: detector");
  ExpectError(base + "evidence: {keypoints_2d: mediapipe}\n", "evidence.keypoints_2d",
              "network | files | both | detector");
}

// evidence.detector_every: tracking needs the detector, a network and refine fallback.
TEST(JobConfig, TrackingNeedsTheDetectorANetworkAndFallback) {
  const std::string tracked =
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: detector, detector_every: 10}\n";
  EXPECT_EQ(LoadJobConfig(WriteJob(tracked)).detector_every, 10);
  EXPECT_EQ(LoadJobConfig(WriteJob(kValidJob)).detector_every, 1);
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: detector, detector_every: 0}\n",
      "evidence.detector_every", ">= 1");
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: files, detector_every: 10}\n",
      "evidence.keypoints_2d", "detector (evidence.detector_every 10 tracks");
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nrefine: {mode: always}\n"
      "evidence: {keypoints_2d: detector, detector_every: 10}\n",
      "network.weights", "a network to track with");
  ExpectError(tracked + "refine: {mode: always}\n", "refine.mode", "fallback");
}

// evidence.detector_palm_tiles: auto (the default, out of the job hash so that jobs
// written before the field keep theirs), off or a count; anything else names the field.
TEST(JobConfig, DetectorPalmTilesAreAutoOffOrACount) {
  const std::string job =
      "input: {path: c}\noutput: {dir: o}\nrefine: {mode: always}\nevidence: "
      "{keypoints_2d: detector";
  const JobConfig by_default = LoadJobConfig(WriteJob(job + "}\n"));
  EXPECT_EQ(by_default.detector_palm_tiles, "auto");
  const JobConfig automatic =
      LoadJobConfig(WriteJob(job + ", detector_palm_tiles: auto}\n"));
  EXPECT_EQ(JobHash(automatic, ""), JobHash(by_default, ""));
  const JobConfig off = LoadJobConfig(WriteJob(job + ", detector_palm_tiles: off}\n"));
  const JobConfig three = LoadJobConfig(WriteJob(job + ", detector_palm_tiles: 3}\n"));
  EXPECT_EQ(off.detector_palm_tiles, "off");
  EXPECT_EQ(three.detector_palm_tiles, "3");
  EXPECT_NE(JobHash(off, ""), JobHash(by_default, ""));
  EXPECT_NE(JobHash(three, ""), JobHash(off, ""));
  for (const char* bad : {"0", "17", "many", "3.5"}) {
    ExpectError(job + ", detector_palm_tiles: " + bad + "}\n",
                "evidence.detector_palm_tiles", "auto, off or 1..16");
  }
}

// evidence.detector_mode: video needs the detector on every frame; per-frame jobs keep
// their hash (the field enters only when set).
TEST(JobConfig, DetectorVideoModeNeedsTheDetectorOnEveryFrame) {
  const std::string fit_only =
      "input: {path: c}\noutput: {dir: o}\nrefine: {mode: always}\n";
  const JobConfig video = LoadJobConfig(
      WriteJob(fit_only + "evidence: {keypoints_2d: detector, detector_mode: video, "
                          "detector_palm_every: 12}\n"));
  EXPECT_TRUE(video.detector_video);
  EXPECT_EQ(video.detector_palm_every, 12);
  const JobConfig per_frame =
      LoadJobConfig(WriteJob(fit_only + "evidence: {keypoints_2d: detector}\n"));
  EXPECT_FALSE(per_frame.detector_video);
  EXPECT_EQ(per_frame.detector_palm_every, 30);
  EXPECT_NE(JobHash(video, ""), JobHash(per_frame, ""));
  JobConfig explicit_frame = per_frame;
  explicit_frame.detector_palm_every = 5;  // read only in video mode
  EXPECT_EQ(JobHash(explicit_frame, ""), JobHash(per_frame, ""));
  ExpectError(fit_only + "evidence: {keypoints_2d: detector, detector_mode: stream}\n",
              "evidence.detector_mode", "frame | video");
  ExpectError(fit_only + "evidence: {keypoints_2d: files, detector_mode: video}\n",
              "evidence.keypoints_2d", "detector (evidence.detector_mode video");
  ExpectError(fit_only +
                  "evidence: {keypoints_2d: detector, detector_mode: video, "
                  "detector_palm_every: -1}\n",
              "evidence.detector_palm_every", ">= 0");
  ExpectError(
      "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n"
      "evidence: {keypoints_2d: detector, detector_every: 10, detector_mode: video}\n",
      "evidence.detector_every", "1 (evidence.detector_mode video");
}

// evidence.detector_max_hands: several hands per frame from the job's own per-frame
// detector; single-hand jobs keep their hash (the field enters only when set).
TEST(JobConfig, DetectorMaxHandsNeedsThePerFrameDetector) {
  const std::string fit_only =
      "input: {path: c}\noutput: {dir: o}\nrefine: {mode: always}\n";
  const JobConfig two = LoadJobConfig(
      WriteJob(fit_only + "evidence: {keypoints_2d: detector, detector_max_hands: 2}\n"));
  EXPECT_EQ(two.detector_max_hands, 2);
  const JobConfig one =
      LoadJobConfig(WriteJob(fit_only + "evidence: {keypoints_2d: detector}\n"));
  EXPECT_EQ(one.detector_max_hands, 1);
  EXPECT_NE(JobHash(two, ""), JobHash(one, ""));
  JobConfig explicit_one = one;
  explicit_one.detector_max_hands = 1;
  EXPECT_EQ(JobHash(explicit_one, ""), JobHash(one, ""));
  ExpectError(fit_only + "evidence: {keypoints_2d: detector, detector_max_hands: 0}\n",
              "evidence.detector_max_hands", ">= 1");
  ExpectError(fit_only + "evidence: {keypoints_2d: files, detector_max_hands: 2}\n",
              "evidence.detector_max_hands", "evidence.keypoints_2d: detector");
  ExpectError(fit_only +
                  "evidence: {keypoints_2d: detector, detector_mode: video, "
                  "detector_max_hands: 2}\n",
              "evidence.detector_max_hands", "video (it tracks one hand)");
}

// The fields `handlabel fit` sets: unset fitter fields stay unset (the fitter's
// defaults), set ones are read and checked naming the field.
TEST(JobConfig, FitSectionAndFileEvidence) {
  const JobConfig plain = LoadJobConfig(WriteJob(kValidJob));
  EXPECT_TRUE(plain.fit.IsDefault());
  EXPECT_EQ(plain.keypoint_files, "auto");
  EXPECT_EQ(plain.max_frames, 0);
  const std::string path = WriteJob(std::string(kValidJob) +
                                    "evidence: {keypoint_files: keypoints, mask_files: "
                                    "truth, ignore_views: [cam01]}\n"
                                    "fit: {init: gt, keypoint_loss: huber, "
                                    "silhouette_rounds: 0, joint_limits: false, "
                                    "mask_margin_px: 1.5}\n");
  const JobConfig job = LoadJobConfig(path);
  EXPECT_EQ(job.keypoint_files, "keypoints");
  EXPECT_EQ(job.mask_files, "truth");
  EXPECT_EQ(job.ignore_views, std::vector<std::string>{"cam01"});
  EXPECT_EQ(job.fit.init, "gt");
  EXPECT_EQ(job.fit.keypoint_loss, std::optional<std::string>("huber"));
  EXPECT_EQ(job.fit.silhouette_rounds, std::optional<int>(0));
  EXPECT_EQ(job.fit.joint_limits, std::optional<bool>(false));
  EXPECT_EQ(job.fit.mask_margin_px, std::optional<double>(1.5));
  EXPECT_FALSE(job.fit.keypoint_sigma_px.has_value());
  EXPECT_FALSE(job.fit.IsDefault());
  // A folder start resolves against the job's folder.
  const std::string with_folder =
      WriteJob(std::string(kValidJob) + "fit: {init: starts}\n");
  const fs::path starts = fs::path(with_folder).parent_path() / "starts";
  fs::create_directories(starts);
  EXPECT_EQ(LoadJobConfig(with_folder).fit.init, starts.string());
}

TEST(JobConfig, FitSectionErrorsNameTheField) {
  const std::string base = "input: {path: c}\noutput: {dir: o}\nnetwork: {weights: w}\n";
  ExpectError(base + "fit: {init: nowhere}\n", "fit.init", "triangulate | gt");
  ExpectError(base + "fit: {keypoint_loss: l1}\n", "fit.keypoint_loss",
              "cauchy | huber | trivial");
  ExpectError(base + "fit: {keypoint_sigma_px: 0}\n", "fit.keypoint_sigma_px", "> 0");
  ExpectError(base + "fit: {pose_pca_comps: 7}\n", "fit.pose_pca_comps", "0, 12 or 45");
  ExpectError(base + "fit: {mask_margin_px: -1}\n", "fit.mask_margin_px", "0..50");
  ExpectError(base + "fit: {rounds: 2}\n", "fit.rounds", "a known key");
  ExpectError(base + "evidence: {keypoint_files: guesses}\n", "evidence.keypoint_files",
              "auto | detections | keypoints");
  ExpectError(
      "input: {path: c, format: ho3d}\noutput: {dir: o}\nnetwork: {weights: "
      "w}\nevidence: {mask_files: truth}\n",
      "evidence.mask_files", "native only");
  ExpectError(
      "input: {path: c, max_frames: -2}\noutput: {dir: o}\nnetwork: {weights: w}\n",
      "input.max_frames", ">= 0");
}

TEST(JobConfig, MissingOrBrokenFileIsAClearError) {
  EXPECT_THROW(LoadJobConfig("/nonexistent/job.yaml"), InputError);
  try {
    LoadJobConfig(WriteJob("input: [unclosed\n"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("valid YAML"));
  }
}

}  // namespace
}  // namespace handlabel
