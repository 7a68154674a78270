#include "pipeline/job_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
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
  ExpectError(base + "refine: {mode: always}\nevidence: {network_mask_sigma_px: -1}\n",
              "evidence.network_mask_sigma_px", "> 0 pixels");
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
