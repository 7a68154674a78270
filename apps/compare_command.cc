#include <chrono>
#include <iostream>
#include <sstream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "comparison/compare_qa.h"
#include "comparison/compare_report.h"
#include "comparison/compare_run.h"
#include "core/errors.h"
#include "pipeline/job_config.h"

namespace handlabel {
namespace {

struct CompareFlags {
  std::string job_file, capture, weights, frames, hand_model;
  int max_frames = 0, threads = 0;
  uint64_t seed = 0;
  std::string methods = "all";
  std::string ablation = "all";
  std::string qa_selection;
  bool quiet = false;
  CompareOptions options;
};

// "none" or a list ("all" is CompareOptions::ablation_all_counts).
std::vector<int> AblationViews(const std::string& text) {
  if (text == "none") return {};
  std::vector<int> views;
  for (const std::string& item : SplitCommas(text)) {
    try {
      views.push_back(std::stoi(item));
    } catch (const std::exception&) {
      throw InputError("command line", "--ablation-views",
                       "all, none or counts like 2,3,4", text);
    }
  }
  return views;
}

// The base job: the YAML job, or the one --capture / --weights describe.
JobConfig BaseJob(const CompareFlags& f) {
  if (!f.job_file.empty()) {
    if (!f.capture.empty()) {
      throw InputError("command line", "--capture",
                       "either --job or --capture, not both");
    }
    return LoadJobConfig(f.job_file);
  }
  if (f.capture.empty()) throw InputError("command line", "--job", "--job or --capture");
  JobConfig job =
      CompareCaptureJob(f.capture, f.weights, f.frames, f.max_frames, f.threads, f.seed);
  job.hand_model = f.hand_model;
  return job;
}

CompareOptions Options(const CompareFlags& f, const JobConfig& base) {
  CompareOptions o = f.options;
  if (o.out_dir.empty()) {
    if (f.job_file.empty()) throw InputError("command line", "--out", "an output folder");
    o.out_dir = base.output_dir + "/compare";
  }
  if (f.methods != "all") {
    for (const std::string& name : SplitCommas(f.methods))
      o.methods.push_back(ParseCompareMethod(name, "command line", "--methods"));
  }
  o.ablation_all_counts = f.ablation == "all";
  if (!o.ablation_all_counts) o.ablation_views = AblationViews(f.ablation);
  if (!f.qa_selection.empty()) o.qa_selection = SplitCommas(f.qa_selection);
  o.Check("command line");
  return o;
}

}  // namespace

int RunCompare(int argc, char** argv) {
  CLI::App app(
      "Run every labeling method on the same frames and compare them against the "
      "ground truth in the POEM paper's table layout (MPVPE, RR-V, PA-V, AUC-V, MPJPE, "
      "RR-J, PA-J, AUC-J), with seconds per frame, threads and network parameters; a "
      "view-count ablation, the quality checks measured against the errors, pictures, "
      "and compare.json / compare.md / report.html (docs/comparison.md).\n"
      "Example: handlabel compare --capture captures/dexycb_synth --weights "
      "models/poem_small_dexycb.pt --max-frames 50 --out compare/dexycb",
      "compare");
  CompareFlags f;
  app.add_option("--job", f.job_file,
                 "a labeling job (YAML): its input, network and "
                 "settings are the base of every method");
  app.add_option("--capture", f.capture, "instead of --job: a native capture folder");
  app.add_option("--weights", f.weights,
                 "with --capture: network checkpoint (empty: "
                 "only the fitting methods run)");
  app.add_option("--frames", f.frames, "with --capture: 'all', 'a:b' or 'id,id,...'");
  app.add_option("--max-frames", f.max_frames, "with --capture: the first N frames")
      ->capture_default_str();
  app.add_option("--threads", f.threads, "with --capture: threads, 0 = all cores")
      ->capture_default_str();
  app.add_option("--seed", f.seed, "with --capture: the jobs' seed")
      ->capture_default_str();
  app.add_option(
      "--hand-model", f.hand_model,
      "with --capture: model file or 'capsule' (default: the shipped open hand)");
  app.add_option("--out", f.options.out_dir,
                 "output folder (default with --job: <output.dir>/compare)");
  app.add_option("--methods", f.methods,
                 "all, or a list of network, network_refine, fit_network_2d, "
                 "fit_detections, fit_exact_2d")
      ->capture_default_str();
  app.add_option("--ablation-views", f.ablation,
                 "view counts for the ablation: all (2 .. views-1), none, or e.g. 2,4")
      ->capture_default_str();
  app.add_option("--ablation-frames", f.options.ablation_frames,
                 "the first N frames enter the ablation")
      ->capture_default_str();
  app.add_option("--auc-max-mm", f.options.auc_max_mm,
                 "PCK / AUC range 0..this (mm); 0 = 50 for HO3D input, else 20")
      ->capture_default_str();
  app.add_option("--worst-frames", f.options.worst_frames,
                 "frames shown with every method's overlay")
      ->capture_default_str();
  app.add_option("--qa-error-mm", f.options.qa_error_mm,
                 "quality-check study: a network answer is bad above this MPJPE")
      ->capture_default_str();
  app.add_option("--qa-selection", f.qa_selection,
                 "quality-check study: earlier compare folders (DIR,DIR,...) whose "
                 "network answers choose the thresholds; this run's frames are then "
                 "all held out (default: choose on even, judge on odd positions)");
  app.add_flag("--quiet", f.quiet, "print only the table and errors");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("compare", [&] {
    const auto start = std::chrono::steady_clock::now();
    const JobConfig base = BaseJob(f);
    const CompareOptions options = Options(f, base);
    const CompareResult result =
        RunComparison(base, options, f.quiet ? nullptr : &std::cerr);
    const MethodRun* network = nullptr;
    for (const MethodRun& run : result.methods) {
      if (run.method == CompareMethod::kNetwork) network = &run;
    }
    QualityStudy qa;
    if (network) {
      qa = StudyQualityChecks(*network, network->job.quality, options.qa_error_mm,
                              options.qa_selection);
    } else {
      qa.why_not = "the network alone was not among the methods";
    }
    const CompareReportFiles files = WriteCompareReport(base, result, qa, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << CompareTableMarkdown(result);
    if (qa.why_not.empty()) {
      std::cout << "quality checks (held-out " << qa.held_out_frames
                << " frames): kept answers with MPJPE > " << qa.error_mm
                << " mm: " << qa.before.kept_bad << "/" << qa.before.kept
                << " with the current "
                << "thresholds, " << qa.after.kept_bad << "/" << qa.after.kept
                << " with the chosen (reprojection " << qa.chosen.max_reprojection_px
                << " px, view agreement " << qa.chosen.max_view_disagreement_mm
                << " mm, chosen on " << qa.selection_frames << " answers)\n";
    }
    std::cout << "report: " << files.html << "\njson: " << files.json
              << "\nmarkdown: " << files.markdown << "\ntime: " << seconds << " s\n";
    int ran = 0;
    for (const MethodRun& run : result.methods) ran += run.why_not.empty();
    return ran > 0 ? 0 : 1;
  });
}

}  // namespace handlabel
