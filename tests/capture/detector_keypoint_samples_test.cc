// Training samples for the detector keypoint model (capture/detector_keypoint_samples.h)
// from a small synthetic capture whose simulated detector marks the model's own
// keypoints (2 px noise, a few wild ones): the triangulated points lie on the truth's
// keypoints, paired with the right frame's parameters.

#include "capture/detector_keypoint_samples.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "capture/native_frame_source.h"
#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

TEST(DetectorKeypointSamples, TriangulatesTheDetectionsBesideTheTruth) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 320;
  o.rig.height = 240;
  o.num_frames = 3;
  o.seed = 46;
  o.num_threads = 1;
  const std::string dir = testing::ScratchDir() + "/capture";
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  const NativeFrameSource source(dir, std::nullopt, "detections");
  const std::vector<DetectorKeypointSample> samples =
      DetectorKeypointSamples(source, source.FrameIds(), {});
  ASSERT_EQ(samples.size(), 3u);
  std::vector<double> distances;
  for (const DetectorKeypointSample& s : samples) {
    const Points3d truth = PoseHand(model, s.truth).keypoints;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (s.found[k]) distances.push_back((s.detected.row(k) - truth.row(k)).norm());
    }
  }
  EXPECT_GT(distances.size(), 3u * kNumHandKeypoints / 2);
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                   distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.005);  // median within 5 mm
}

}  // namespace
}  // namespace handlabel
