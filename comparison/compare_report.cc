#include "comparison/compare_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/atomic_file.h"
#include "core/json_util.h"
#include "image/html_report.h"
#include "pipeline/build_info.h"
#include "comparison/compare_pictures.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The main table's columns: the paper's eight metrics, then speed and size.
struct Column {
  const char* key;
  const char* title;
  int decimals;
};
const std::vector<Column> kColumns = {{"mpvpe_mm", "MPVPE", 2},
                                      {"rr_mpvpe_mm", "RR-V", 2},
                                      {"pa_mpvpe_mm", "PA-V", 2},
                                      {"auc_v", "AUC-V", 3},
                                      {"mpjpe_mm", "MPJPE", 2},
                                      {"rr_mpjpe_mm", "RR-J", 2},
                                      {"pa_mpjpe_mm", "PA-J", 2},
                                      {"auc_j", "AUC-J", 3},
                                      {"accel_error_mm", "Accel-J", 2},
                                      {"jitter_mm", "Jitter-J", 2},
                                      {"seconds_per_frame", "s/frame", 3},
                                      {"threads", "threads", 0},
                                      {"parameters", "params", 0},
                                      {"frames", "frames", 0}};

// The row's numbers by column key (NaN where there is none).
std::map<std::string, double> RowValues(const MethodRun& run) {
  std::map<std::string, double> v;
  for (const Column& c : kColumns) v[c.key] = kNaN;
  if (!MethodRan(run)) return v;
  v["seconds_per_frame"] = run.seconds_per_frame;
  v["threads"] = run.threads;
  v["parameters"] = run.parameters > 0 ? double(run.parameters) : kNaN;
  v["frames"] = run.scores.frames.size();
  if (!run.has_truth) return v;
  const HandFrameMetrics& m = run.scores.mean;
  v["mpjpe_mm"] = 1000 * m.mpjpe;
  v["rr_mpjpe_mm"] = 1000 * m.rr_mpjpe;
  v["pa_mpjpe_mm"] = 1000 * m.pa_mpjpe;
  v["auc_j"] = run.scores.joint_pck.auc;
  if (run.scores.motion.triples > 0) {
    v["accel_error_mm"] = 1000 * run.scores.motion.acceleration_error;
    v["jitter_mm"] = 1000 * run.scores.motion.jitter;
  }
  if (MethodHasVertices(run)) {
    v["mpvpe_mm"] = 1000 * m.mpvpe;
    v["rr_mpvpe_mm"] = 1000 * m.rr_mpvpe;
    v["pa_mpvpe_mm"] = 1000 * m.pa_mpvpe;
    v["auc_v"] = run.scores.vertex_pck.auc;
  }
  return v;
}

std::string Note(const MethodRun& run) {
  if (!MethodRan(run)) return "not run: " + run.why_not;
  std::string note = run.evidence;
  if (run.failed > 0) note += "; " + std::to_string(run.failed) + " failed";
  if (!run.has_truth) note += "; no ground truth";
  return note;
}

nlohmann::json QaJson(const QualityStudy& qa) {
  nlohmann::json j = {{"error_mm", qa.error_mm}, {"why_not", qa.why_not}};
  if (!qa.why_not.empty()) return j;
  j["frames"] = qa.frames;
  j["selection_frames"] = qa.selection_frames;
  j["held_out_frames"] = qa.held_out_frames;
  j["bad_frames"] = qa.bad_frames;
  for (const CheckStudy& c : qa.checks) {
    j["checks"].push_back({{"name", c.name},
                           {"unit", c.unit},
                           {"current", c.current},
                           {"chosen", c.chosen},
                           {"roc_auc", JsonNumberOrNull(c.roc_auc)},
                           {"precision_current", c.precision_current},
                           {"recall_current", c.recall_current},
                           {"precision_chosen", c.precision_chosen},
                           {"recall_chosen", c.recall_chosen}});
  }
  auto share = [](const KeptShare& s) {
    return nlohmann::json{{"answers", s.answers},
                          {"kept", s.kept},
                          {"kept_bad", s.kept_bad},
                          {"share", s.Share()},
                          {"kept_fraction", s.KeptFraction()}};
  };
  j["selection_dirs"] = qa.selection_dirs;
  j["held_out_before"] = share(qa.before);
  j["held_out_after"] = share(qa.after);
  return j;
}

// ---- tables ----

HtmlTable ResultsTable(const CompareResult& r) {
  HtmlTable t;
  t.id = "results";
  t.header = {"method"};
  for (const Column& c : kColumns) t.header.push_back(c.title);
  t.header.push_back("note");
  for (size_t i = 0; i < r.methods.size(); ++i) {
    const MethodRun& run = r.methods[i];
    std::vector<HtmlCell> row = {
        {Describe(run.method) + " [" + ToString(run.method) + "]"}};
    const std::map<std::string, double> values = RowValues(run);
    for (const Column& c : kColumns) {
      row.push_back({FormatFixed(values.at(c.key), c.decimals),
                     "methods." + std::to_string(i) + ".metrics." + c.key, c.decimals});
    }
    row.push_back({Note(run)});
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::vector<int> AblationViews(const CompareResult& r) {
  std::vector<int> views;
  for (const AblationCell& c : r.ablation) views.push_back(c.views);
  std::sort(views.begin(), views.end());
  views.erase(std::unique(views.begin(), views.end()), views.end());
  return views;
}

HtmlTable AblationTable(const CompareResult& r) {
  HtmlTable t;
  t.id = "ablation";
  t.header = {"method"};
  const std::vector<int> views = AblationViews(r);
  for (int v : views) t.header.push_back(std::to_string(v) + " views MPJPE");
  std::vector<CompareMethod> methods;
  for (const AblationCell& c : r.ablation) {
    if (std::find(methods.begin(), methods.end(), c.method) == methods.end())
      methods.push_back(c.method);
  }
  for (CompareMethod m : methods) {
    std::vector<HtmlCell> row = {{ToString(m)}};
    for (int v : views) {
      HtmlCell cell{"-"};
      for (size_t i = 0; i < r.ablation.size(); ++i) {
        const AblationCell& c = r.ablation[i];
        if (c.method != m || c.views != v) continue;
        if (!c.why_not.empty() || c.frames == 0) {
          cell.text = "not run";
        } else {
          cell = {FormatFixed(c.mpjpe_mm, 2),
                  "ablation." + std::to_string(i) + ".mpjpe_mm", 2};
        }
      }
      row.push_back(cell);
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

HtmlTable QaTable(const QualityStudy& qa) {
  HtmlTable t;
  t.id = "qa";
  t.header = {"check",
              "current",
              "chosen",
              "ROC AUC",
              "precision (current)",
              "recall (current)",
              "precision (chosen)",
              "recall (chosen)"};
  for (size_t i = 0; i < qa.checks.size(); ++i) {
    const CheckStudy& c = qa.checks[i];
    const std::string p = "qa.checks." + std::to_string(i) + ".";
    t.rows.push_back({{c.name + " (" + c.unit + ")"},
                      {FormatFixed(c.current, 2), p + "current", 2},
                      {FormatFixed(c.chosen, 2), p + "chosen", 2},
                      {FormatFixed(c.roc_auc, 3), p + "roc_auc", 3},
                      {FormatFixed(c.precision_current, 3), p + "precision_current", 3},
                      {FormatFixed(c.recall_current, 3), p + "recall_current", 3},
                      {FormatFixed(c.precision_chosen, 3), p + "precision_chosen", 3},
                      {FormatFixed(c.recall_chosen, 3), p + "recall_chosen", 3}});
  }
  return t;
}

HtmlTable QaShareTable(const QualityStudy& qa) {
  HtmlTable t;
  t.id = "qa_share";
  t.header = {"thresholds", "kept answers", "kept of all",
              "kept with MPJPE > " + FormatFixed(qa.error_mm, 0) + " mm", "share"};
  auto row = [](const char* name, const KeptShare& s, const std::string& key) {
    return std::vector<HtmlCell>{
        {name},
        {std::to_string(s.kept), "qa." + key + ".kept", 0},
        {FormatFixed(s.KeptFraction(), 3), "qa." + key + ".kept_fraction", 3},
        {std::to_string(s.kept_bad), "qa." + key + ".kept_bad", 0},
        {FormatFixed(s.Share(), 3), "qa." + key + ".share", 3}};
  };
  t.rows.push_back(row("current (before)", qa.before, "held_out_before"));
  t.rows.push_back(row("chosen (after)", qa.after, "held_out_after"));
  return t;
}

std::string MarkdownTable(const HtmlTable& t) {
  std::string md = "|";
  for (const std::string& h : t.header) md += " " + h + " |";
  md += "\n|";
  for (size_t i = 0; i < t.header.size(); ++i) md += "---|";
  md += "\n";
  for (const auto& row : t.rows) {
    md += "|";
    for (const HtmlCell& c : row) md += " " + c.text + " |";
    md += "\n";
  }
  return md;
}

std::string JobText(const JobConfig& base, const CompareResult& r) {
  std::string text =
      "job: " + base.name + " (" + base.source_file + ")\ninput: " + r.input +
      "\nframes: " + std::to_string(r.frames.size()) + " (" +
      (r.frames.empty() ? "" : r.frames.front() + " .. " + r.frames.back()) +
      ")\ncameras: " + std::to_string(r.cameras.size()) + "\nnetwork.weights: " +
      (base.network_weights.empty() ? "none" : base.network_weights) +
      "\nhand_model: " + (base.hand_model.empty() ? "default" : base.hand_model) +
      "\nseed: " + std::to_string(base.seed) + "\nPCK / AUC range: 0-" +
      FormatFixed(r.auc_max_mm, 0) + " mm\n";
  for (const MethodRun& run : r.methods) {
    text += ToString(run.method) + ": " +
            (MethodRan(run) ? run.evidence + ", labels in " + run.output_dir
                            : "not run: " + run.why_not) +
            "\n";
  }
  return text;
}

std::string VersionsText() {
  const BuildInfo build = GetBuildInfo();
  std::string text = "handlabel " + build.version + " (" + build.git_hash + ", " +
                     build.build_type + ")\n";
  for (const auto& [name, version] : build.dependencies)
    text += name + " " + version + "\n";
  return text;
}

}  // namespace

nlohmann::json MethodJson(const MethodRun& run) {
  nlohmann::json m = {{"method", ToString(run.method)},
                      {"title", Describe(run.method)},
                      {"ran", MethodRan(run)},
                      {"why_not", run.why_not},
                      {"evidence", run.evidence},
                      {"output_dir", run.output_dir},
                      {"labelled", run.ok},
                      {"failed", run.failed},
                      {"wall_seconds", run.wall_seconds},
                      {"by_path", run.by_path}};
  for (const auto& [key, value] : RowValues(run))
    m["metrics"][key] = JsonNumberOrNull(value);
  if (!run.has_truth) return m;
  m["pck_thresholds_mm"] = Millimetres(run.scores.joint_pck.thresholds);
  m["joint_pck"] = run.scores.joint_pck.pck;
  if (MethodHasVertices(run)) m["vertex_pck"] = run.scores.vertex_pck.pck;
  const Eigen::VectorXd per_joint = 1000 * run.scores.joint_errors.colwise().mean();
  m["per_keypoint_mm"] =
      std::vector<double>(per_joint.data(), per_joint.data() + per_joint.size());
  for (size_t f = 0; f < run.scores.frames.size(); ++f) {
    m["per_frame_mpjpe_mm"][run.scores.frames[f]] = 1000 * run.scores.per_frame[f].mpjpe;
  }
  return m;
}

nlohmann::json CompareToJson(const JobConfig& base, const CompareResult& r,
                             const QualityStudy& qa) {
  nlohmann::json j;
  j["format"] = "handlabel-compare";
  j["version"] = 1;
  j["job"] = base.name;
  j["job_file"] = base.source_file;
  j["input"] = r.input;
  j["seed"] = base.seed;
  j["frames"] = r.frames;
  j["cameras"] = r.cameras;
  j["auc_range_mm"] = {0.0, r.auc_max_mm};
  j["wall_seconds"] = r.wall_seconds;
  for (const Column& c : kColumns)
    j["columns"].push_back(
        {{"key", c.key}, {"title", c.title}, {"decimals", c.decimals}});
  for (const MethodRun& run : r.methods) j["methods"].push_back(MethodJson(run));
  j["ablation"] = nlohmann::json::array();
  for (const AblationCell& c : r.ablation) {
    j["ablation"].push_back({{"method", ToString(c.method)},
                             {"views", c.views},
                             {"why_not", c.why_not},
                             {"frames", c.frames},
                             {"mpjpe_mm", JsonNumberOrNull(c.mpjpe_mm)},
                             {"mpvpe_mm", JsonNumberOrNull(c.mpvpe_mm)},
                             {"seconds_per_frame", c.seconds_per_frame}});
  }
  j["qa"] = QaJson(qa);
  const BuildInfo build = GetBuildInfo();
  j["versions"] = {{"handlabel", build.version}, {"git_hash", build.git_hash}};
  for (const auto& [name, version] : build.dependencies) j["versions"][name] = version;
  return j;
}

std::string CompareTableMarkdown(const CompareResult& r) {
  return MarkdownTable(ResultsTable(r));
}

CompareReportFiles WriteCompareReport(const JobConfig& base, const CompareResult& r,
                                      const QualityStudy& qa,
                                      const CompareOptions& options) {
  CompareReportFiles files;
  const fs::path out(options.out_dir);
  files.json = (out / "compare.json").string();
  files.markdown = (out / "compare.md").string();
  files.html = (out / "report.html").string();
  files.pictures_dir = (out / "pictures").string();
  WriteFileAtomically(files.json, CompareToJson(base, r, qa).dump(1) + "\n");

  HtmlPage page("handlabel compare: " + base.name);
  std::string md = "# handlabel compare: " + base.name + "\n\n";
  const std::string intro =
      std::to_string(r.frames.size()) + " frames of " + r.input + "; errors in mm, AUC " +
      "over 0-" + FormatFixed(r.auc_max_mm, 0) +
      " mm (the POEM paper's Table 1 layout: RR = root-relative, PA = Procrustes-"
      "aligned); s/frame = per-frame time summed over the job's threads.";
  page.Heading("Results");
  page.Paragraph(intro);
  const HtmlTable results = ResultsTable(r);
  page.Table(results);
  md += intro + "\n\n" + MarkdownTable(results) + "\n";

  auto picture = [&](const std::string& name, const ImageU8& image,
                     const std::string& caption) {
    if (image.empty()) return;
    const std::string path = (fs::path(files.pictures_dir) / (name + ".png")).string();
    WriteFileAtomically(path, EncodePng(image));
    page.Image(image, caption);
    md += "![" + caption + "](pictures/" + name + ".png)\n\n";
  };
  if (!ScoredMethods(r).empty()) {
    page.Heading("Pictures");
    md += "## Pictures\n\n";
    picture("pck", PckPicture(r), "3D PCK curves of every method");
    picture("per_joint", PerJointPicture(r), "mean error per keypoint");
    picture("histogram", HistogramPicture(r), "per-frame MPJPE histogram");
    picture("time_accuracy", TimeAccuracyPicture(r), "time vs accuracy");
    picture("worst_frames", WorstFramesPicture(base, r, options.worst_frames),
            "worst frames (by the first method's MPJPE): truth and every method");
  }
  if (!r.ablation.empty()) {
    page.Heading("View-count ablation");
    const std::string text =
        "The first k cameras keep their 2D evidence, the others are ignored "
        "(evidence.ignore_views); first " +
        std::to_string(std::min<size_t>(options.ablation_frames, r.frames.size())) +
        " frames.";
    page.Paragraph(text);
    const HtmlTable ablation = AblationTable(r);
    page.Table(ablation);
    md += "## View-count ablation\n\n" + text + "\n\n" + MarkdownTable(ablation) + "\n";
    picture("ablation", AblationPicture(r), "MPJPE against the number of views");
  }
  page.Heading("Quality checks against the truth");
  md += "## Quality checks against the truth\n\n";
  if (!qa.why_not.empty()) {
    page.Paragraph("No study: " + qa.why_not);
    md += "No study: " + qa.why_not + "\n\n";
  } else {
    std::string chosen_on =
        std::to_string(qa.selection_frames) + " frames (even positions), judged on the " +
        std::to_string(qa.held_out_frames) + " held-out frames (odd positions).";
    if (!qa.selection_dirs.empty()) {
      std::string dirs;
      for (const std::string& d : qa.selection_dirs)
        dirs += (dirs.empty() ? "" : ", ") + d;
      chosen_on = std::to_string(qa.selection_frames) + " network answers of " + dirs +
                  ", judged on all " + std::to_string(qa.held_out_frames) +
                  " answers of this run (held out).";
    }
    const std::string text = std::to_string(qa.frames) + " network answers, " +
                             std::to_string(qa.bad_frames) + " with MPJPE > " +
                             FormatFixed(qa.error_mm, 0) +
                             " mm. Thresholds chosen by Youden's J on " + chosen_on;
    page.Paragraph(text);
    const HtmlTable checks = QaTable(qa), share = QaShareTable(qa);
    page.Table(checks);
    page.Table(share);
    md += text + "\n\n" + MarkdownTable(checks) + "\n" + MarkdownTable(share) + "\n";
    picture("qa_scatter", QaScatterPicture(qa), "check value against the answer's MPJPE");
    picture("qa_roc", QaRocPicture(qa), "ROC of each check");
  }
  page.Heading("Job");
  page.Preformatted(JobText(base, r));
  page.Heading("Versions");
  page.Preformatted(VersionsText());
  md += "## Job\n\n```\n" + JobText(base, r) + "```\n\n## Versions\n\n```\n" +
        VersionsText() + "```\n";
  WriteFileAtomically(files.markdown, md);
  WriteFileAtomically(files.html, page.ToString());
  return files;
}

}  // namespace handlabel
