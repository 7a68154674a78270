#pragma once
// What `handlabel compare` writes: one table in the POEM paper's layout (Table 1:
// MPVPE, RR-V, PA-V, AUC-V, MPJPE, RR-J, PA-J, AUC-J; errors in mm, AUC over the
// comparison's PCK range), the keypoints' acceleration error and jitter over
// consecutive frames (Accel-J, Jitter-J, mm/frame^2; empty when no three compared
// frames follow each other), seconds per frame, threads and network parameters per
// method, the view-count ablation, the quality-check study and the pictures:
//   <out>/compare.json    every number (the HTML and Markdown show these, rounded)
//   <out>/compare.md      the tables, for terminals and docs
//   <out>/report.html     one self-contained page (inline CSS, images as data: URIs):
//                         tables, pictures, the job and the versions
//   <out>/pictures/*.png  the pictures as files: pck, per_joint, histogram,
//                         time_accuracy, worst_frames, ablation, qa_scatter, qa_roc

#include <nlohmann/json.hpp>
#include <string>

#include "comparison/compare_qa.h"
#include "comparison/compare_run.h"

namespace handlabel {

struct CompareReportFiles {
  std::string json, markdown, html, pictures_dir;
};

// One method's row as JSON: its metrics by column key (mm, AUC; null where there is
// none), PCK curves, per-keypoint and per-frame errors, how it ran. compare.json's
// "methods" entries and `eval-network --capture --json` (one writer for both).
nlohmann::json MethodJson(const MethodRun& run);

// The result as JSON (the numbers the report shows).
nlohmann::json CompareToJson(const JobConfig& base, const CompareResult& result,
                             const QualityStudy& qa);

// The main table as Markdown (what the command prints).
std::string CompareTableMarkdown(const CompareResult& result);

// Writes every file above (each atomically) and returns their paths. `worst_frames`:
// how many frames the overlay picture shows.
CompareReportFiles WriteCompareReport(const JobConfig& base, const CompareResult& result,
                                      const QualityStudy& qa,
                                      const CompareOptions& options);

}  // namespace handlabel
