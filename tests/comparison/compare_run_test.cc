// Which job each compared method runs as (comparison/compare_run.h).

#include <gtest/gtest.h>

#include "core/errors.h"
#include "comparison/compare_run.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

JobConfig Base() {
  JobConfig job = CompareCaptureJob("/data/capture", "/data/poem.pt", "", 0, 2, 7);
  return job;
}

TEST(CompareRun, NetworkMethodsNeedWeights) {
  const JobConfig no_weights = CompareCaptureJob("/data/capture", "", "", 0, 2, 7);
  for (CompareMethod m : {CompareMethod::kNetwork, CompareMethod::kNetworkRefine,
                          CompareMethod::kFitNetwork2d}) {
    std::string why;
    MethodJob(no_weights, m, "/tmp/out", &why);
    EXPECT_NE(why.find("no network weights"), std::string::npos) << ToString(m);
  }
}

TEST(CompareRun, EachMethodIsALabelJob) {
  std::string why;
  const JobConfig network = MethodJob(Base(), CompareMethod::kNetwork, "/o", &why);
  EXPECT_TRUE(why.empty());
  EXPECT_EQ(network.refine_mode, RefineMode::kOff);
  EXPECT_EQ(network.output_dir, "/o/methods/network");
  EXPECT_EQ(network.seed, 7u);

  const JobConfig refine = MethodJob(Base(), CompareMethod::kNetworkRefine, "/o", &why);
  EXPECT_EQ(refine.refine_mode, RefineMode::kAlways);
  EXPECT_EQ(refine.keypoints, KeypointSource::kBoth);

  // The paper's baseline: every frame falls back to a fit from the network's 2D.
  const JobConfig baseline = MethodJob(Base(), CompareMethod::kFitNetwork2d, "/o", &why);
  EXPECT_EQ(baseline.refine_mode, RefineMode::kFallback);
  EXPECT_GT(baseline.quality.min_views, 1000);
  EXPECT_EQ(baseline.keypoints, KeypointSource::kNetwork);
  EXPECT_EQ(baseline.masks, MaskSource::kNetwork);
  EXPECT_EQ(baseline.fit.init, "triangulate");

  const JobConfig fit = MethodJob(Base(), CompareMethod::kFitDetections, "/o", &why);
  EXPECT_TRUE(fit.network_weights.empty());
  EXPECT_EQ(fit.refine_mode, RefineMode::kAlways);
  EXPECT_EQ(fit.keypoints, KeypointSource::kFiles);
  EXPECT_EQ(fit.keypoint_files, "auto");
}

TEST(CompareRun, ExactTwoDNeedsASyntheticNativeCapture) {
  JobConfig base = Base();
  base.input_format = "dexycb";
  std::string why;
  MethodJob(base, CompareMethod::kFitExact2d, "/o", &why);
  EXPECT_NE(why.find("synthetic"), std::string::npos) << why;
  base.input_format = "ho3d";
  MethodJob(base, CompareMethod::kFitDetections, "/o", &why);
  EXPECT_NE(why.find("no 2D keypoint files"), std::string::npos) << why;
}

TEST(CompareRun, MethodNamesRoundTrip) {
  for (CompareMethod m : AllCompareMethods())
    EXPECT_EQ(ParseCompareMethod(ToString(m), "t", "f"), m);
  EXPECT_THROW(ParseCompareMethod("magic", "t", "--methods"), InputError);
}

TEST(CompareRun, OptionsAreChecked) {
  CompareOptions o;
  EXPECT_THROW(o.Check("test"), InputError);  // no folder
  o.out_dir = "/tmp/x";
  EXPECT_NO_THROW(o.Check("test"));
  o.ablation_frames = 0;
  EXPECT_THROW(o.Check("test"), InputError);
}

}  // namespace
}  // namespace handlabel
