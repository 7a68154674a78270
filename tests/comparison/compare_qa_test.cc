// The quality-check study on answers whose truth is known by construction: a check
// whose value grows with the error must be found (ROC AUC 1), and the threshold
// chosen from it must keep fewer bad answers than a loose current one.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "comparison/compare_qa.h"
#include "comparison/compare_report.h"
#include "pipeline/label_record.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

QualityFlag Flag(const std::string& name, double value, double threshold) {
  return {name, value <= threshold, value, threshold, ""};
}

// A network run of n frames: frame f has MPJPE error_mm(f) and reprojection value
// 2 x that (a perfect detector), view agreement 5 mm (uninformative).
MethodRun NetworkRun(const std::string& dir, int n, const QualityThresholds& t) {
  MethodRun run;
  run.method = CompareMethod::kNetwork;
  run.output_dir = dir;
  for (int f = 0; f < n; ++f) {
    const double error_mm = 2.0 + f;  // 2 .. n+1 mm
    LabelRecord label;
    label.frame = "f" + std::to_string(100 + f);
    label.mesh.keypoints = Points3d::Zero(21, 3);
    label.mesh.vertices = Points3d::Zero(0, 3);
    label.mesh.joints = Points3d::Zero(16, 3);
    label.quality.flags = {{"finite", true, 0, 0, ""},
                           {"range", true, 0.2, 0.35, ""},
                           {"enough_views", true, 8, 2, ""},
                           Flag("reprojection", 2 * error_mm, t.max_reprojection_px),
                           Flag("view_agreement", 5.0, t.max_view_disagreement_mm)};
    WriteLabelFiles(dir, label, Faces(0, 3), {});
    run.scores.frames.push_back(label.frame);
    HandFrameMetrics m;
    m.mpjpe = error_mm / 1000;
    run.scores.per_frame.push_back(m);
  }
  return run;
}

TEST(CompareQa, FindsThePerfectCheckAndKeepsFewerBadAnswers) {
  QualityThresholds loose;
  loose.max_reprojection_px = 40;  // keeps answers up to 20 mm
  const MethodRun run = NetworkRun(testing::ScratchDir(), 20, loose);  // 2 .. 21 mm
  const QualityStudy s = StudyQualityChecks(run, loose, 8.0);
  ASSERT_TRUE(s.why_not.empty()) << s.why_not;
  EXPECT_EQ(s.frames, 20);
  EXPECT_EQ(s.selection_frames, 10);
  EXPECT_EQ(s.held_out_frames, 10);
  EXPECT_EQ(s.bad_frames, 13);  // 9 .. 21 mm
  ASSERT_EQ(s.checks.size(), 2u);
  const CheckStudy& reprojection = s.checks[0];
  EXPECT_EQ(reprojection.name, "reprojection");
  EXPECT_DOUBLE_EQ(reprojection.roc_auc, 1.0);
  // Separates 8 mm (16 px) from 9 mm (18 px) on the selection frames (even positions:
  // 2, 4, 6, 8, 10, ... mm), so the chosen threshold lies in [16, 20) px.
  EXPECT_GE(reprojection.chosen, 16.0);
  EXPECT_LT(reprojection.chosen, 20.0);
  EXPECT_DOUBLE_EQ(reprojection.recall_chosen, 1.0);
  EXPECT_DOUBLE_EQ(reprojection.precision_chosen, 1.0);
  // Held out (odd positions: 3, 5, ..., 21 mm): the loose threshold keeps 3..19 mm
  // (9 answers, 6 of them bad), the chosen one 3, 5, 7 mm (none bad).
  EXPECT_EQ(s.before.kept, 9);
  EXPECT_EQ(s.before.kept_bad, 6);
  EXPECT_EQ(s.after.kept, 3);
  EXPECT_EQ(s.after.kept_bad, 0);
  EXPECT_LT(s.after.Share(), s.before.Share());
  // The uninformative check keeps its threshold (J = 0 everywhere) or any value:
  // it must not flag good answers more than bad ones.
  EXPECT_LE(s.checks[1].roc_auc, 0.5 + 1e-12);
}

// Thresholds chosen on an earlier comparison's answers (its compare.json and labels,
// written here as compare writes them), judged on every answer of this run.
TEST(CompareQa, ChoosesOnEarlierComparisonsAndHoldsOutThisRun) {
  QualityThresholds loose;
  loose.max_reprojection_px = 40;
  const std::string scratch = testing::ScratchDir();  // one per test: call once
  const std::string selection_dir = scratch + "/selection";
  MethodRun selection = NetworkRun(selection_dir + "/methods/network", 20, loose);
  selection.has_truth = true;  // 2 .. 21 mm
  {
    std::ofstream out(selection_dir + "/compare.json");
    out << nlohmann::json{{"methods", {MethodJson(selection)}}}.dump();
  }
  ASSERT_TRUE(std::filesystem::exists(selection_dir + "/compare.json"));
  const MethodRun run = NetworkRun(scratch + "/run", 10, loose);  // 2 .. 11 mm
  const QualityStudy s = StudyQualityChecks(run, loose, 8.0, {selection_dir});
  ASSERT_TRUE(s.why_not.empty()) << s.why_not;
  EXPECT_EQ(s.selection_frames, 20);
  EXPECT_EQ(s.held_out_frames, 10);
  // All 20 selection answers separate 8 mm (16 px) from 9 mm (18 px).
  EXPECT_GE(s.chosen.max_reprojection_px, 16.0);
  EXPECT_LT(s.chosen.max_reprojection_px, 18.0);
  // Every answer of this run is held out: before, all 10 kept (9, 10, 11 mm bad);
  // after, 2 .. 8 mm kept, none bad.
  EXPECT_EQ(s.before.answers, 10);
  EXPECT_EQ(s.before.kept, 10);
  EXPECT_EQ(s.before.kept_bad, 3);
  EXPECT_EQ(s.after.kept, 7);
  EXPECT_EQ(s.after.kept_bad, 0);
  EXPECT_DOUBLE_EQ(s.after.KeptFraction(), 0.7);
  // A folder without compare.json is named in the error.
  try {
    StudyQualityChecks(run, loose, 8.0, {selection_dir + "/nothing"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nothing/compare.json"), std::string::npos)
        << e.what();
  }
}

TEST(CompareQa, NoStudyWithoutTheNetworkRow) {
  MethodRun run;
  run.method = CompareMethod::kFitDetections;
  EXPECT_FALSE(StudyQualityChecks(run, {}, 8.0).why_not.empty());
  run.method = CompareMethod::kNetwork;
  run.why_not = "no network weights";
  EXPECT_NE(StudyQualityChecks(run, {}, 8.0).why_not.find("no network weights"),
            std::string::npos);
}

}  // namespace
}  // namespace handlabel
