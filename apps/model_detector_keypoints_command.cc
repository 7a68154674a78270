// `handlabel model detector-keypoints`: learn where a 2D detector puts its keypoints on
// the hand model (hand/detector_keypoints.h) from synthetic captures with exact truth
// that the detector has been run on (docs/fitting.md "Where the detector's keypoints
// are").

#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "capture/detector_keypoint_samples.h"
#include "capture/native_frame_source.h"
#include "hand/detector_keypoints.h"
#include "hand/metrics.h"
#include "pipeline/hand_model_source.h"

namespace handlabel {
namespace {

// Mean distance between the triangulated detections and the model's keypoints, or the
// detector keypoints of `model` when given, over the found ones (mm).
double MeanDistanceMm(const HandModel& hand, const std::vector<DetectorKeypointSample>& s,
                      const DetectorKeypointModel* model) {
  double sum = 0;
  int count = 0;
  for (const DetectorKeypointSample& sample : s) {
    const HandMesh mesh = PoseHand(hand, sample.truth);
    const Points3d k = model ? DetectorKeypointsOfMesh(*model, mesh) : mesh.keypoints;
    for (int i = 0; i < kNumHandKeypoints; ++i) {
      if (!sample.found[i]) continue;
      sum += (k.row(i) - sample.detected.row(i)).norm();
      ++count;
    }
  }
  return count ? 1000 * sum / count : 0;
}

}  // namespace

int RunModelDetectorKeypoints(int argc, char** argv) {
  CLI::App app(
      "Learn where a 2D detector puts its 21 keypoints on the hand model (per keypoint a "
      "weighted sum of offsets to nearby mesh vertices) from synthetic captures with "
      "ground truth that `handlabel detect` has been run on. Writes the model file that "
      "the smoothing pass reads (sequence.detector_keypoints).\n"
      "Example: handlabel model detector-keypoints --capture synth/s46 --capture "
      "synth/s47 --out models/detector_keypoints_mediapipe.json",
      "model detector-keypoints");
  std::vector<std::string> captures;
  std::string out, detector = "mediapipe";
  LearnDetectorKeypointsOptions learn;
  DetectorKeypointSampleOptions sample_options;
  app.add_option("--capture", captures,
                 "native capture with ground truth and detections (repeat the flag)")
      ->required();
  app.add_option("--out", out, "model file to write (.json)")->required();
  app.add_option("--detector", detector, "whose keypoints, recorded in the file");
  app.add_option("--vertices", learn.vertices_per_keypoint,
                 "mesh vertices per keypoint (nearest on the flat mean hand)");
  app.add_option("--ridge", learn.ridge, "ridge on the weights, relative");
  app.add_option("--min-views", sample_options.min_views,
                 "views that must agree on a triangulated keypoint");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("model detector-keypoints", [&] {
    std::vector<DetectorKeypointSample> samples;
    std::optional<HandSide> side;
    std::ostringstream learned;
    learned << "handlabel model detector-keypoints --vertices "
            << learn.vertices_per_keypoint << " --ridge " << learn.ridge
            << " --min-views " << sample_options.min_views << " on";
    for (const std::string& dir : captures) {
      const NativeFrameSource source(dir, std::nullopt, "detections");
      side = source.side();
      const std::vector<DetectorKeypointSample> s =
          DetectorKeypointSamples(source, source.FrameIds(), sample_options);
      samples.insert(samples.end(), s.begin(), s.end());
      // The folder's name, not its path: the file is shipped (models/NOTICE.*).
      learned << " " << std::filesystem::path(dir).filename().string() << " (" << s.size()
              << " frames)";
    }
    const HandModel hand = ResolveHandModel("", side).model;
    const DetectorKeypointModel model =
        LearnDetectorKeypoints(hand, samples, learn, detector, learned.str());
    WriteDetectorKeypointModel(out, model);
    std::cout << "wrote " << out << " from " << samples.size()
              << " frames: detections to the model's keypoints "
              << MeanDistanceMm(hand, samples, nullptr) << " mm, to the learned ones "
              << MeanDistanceMm(hand, samples, &model) << " mm (mean)\n";
    return 0;
  });
}

}  // namespace handlabel
