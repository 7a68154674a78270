#include "pipeline/compare_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/atomic_file.h"
#include "core/draw.h"
#include "core/html_report.h"
#include "core/image_file.h"
#include "core/json_util.h"
#include "core/line_plot.h"
#include "pipeline/build_info.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/label_overlay.h"
#include "pipeline/label_stage_factory.h"

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
                                      {"seconds_per_frame", "s/frame", 3},
                                      {"threads", "threads", 0},
                                      {"parameters", "params", 0},
                                      {"frames", "frames", 0}};

std::string Number(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

bool Ran(const MethodRun& run) { return run.why_not.empty(); }
bool HasVertices(const MethodRun& run) { return run.scores.vertex_errors.cols() > 0; }

// The row's numbers by column key (NaN where there is none).
std::map<std::string, double> RowValues(const MethodRun& run) {
  std::map<std::string, double> v;
  for (const Column& c : kColumns) v[c.key] = kNaN;
  if (!Ran(run)) return v;
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
  if (HasVertices(run)) {
    v["mpvpe_mm"] = 1000 * m.mpvpe;
    v["rr_mpvpe_mm"] = 1000 * m.rr_mpvpe;
    v["pa_mpvpe_mm"] = 1000 * m.pa_mpvpe;
    v["auc_v"] = run.scores.vertex_pck.auc;
  }
  return v;
}

std::string Note(const MethodRun& run) {
  if (!Ran(run)) return "not run: " + run.why_not;
  std::string note = run.evidence;
  if (run.failed > 0) note += "; " + std::to_string(run.failed) + " failed";
  if (!run.has_truth) note += "; no ground truth";
  return note;
}

std::vector<double> Mm(std::vector<double> v) {
  for (double& x : v) x *= 1000;
  return v;
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

// ---- pictures ----

PlotOptions Plot(const std::string& title, const std::string& x, const std::string& y) {
  PlotOptions o;
  o.width = 720;
  o.height = 400;
  o.title = title;
  o.x_label = x;
  o.y_label = y;
  return o;
}

std::vector<const MethodRun*> Scored(const CompareResult& r) {
  std::vector<const MethodRun*> runs;
  for (const MethodRun& run : r.methods) {
    if (Ran(run) && run.has_truth) runs.push_back(&run);
  }
  return runs;
}

int ColorOf(CompareMethod m) { return static_cast<int>(m); }

ImageU8 PckPicture(const CompareResult& r) {
  std::vector<PlotSeries> joints, vertices;
  for (const MethodRun* run : Scored(r)) {
    const MethodScores& s = run->scores;
    joints.push_back({ToString(run->method) + " AUC " + Number(s.joint_pck.auc, 3),
                      Mm(s.joint_pck.thresholds), s.joint_pck.pck,
                      PlotColor(ColorOf(run->method))});
    if (HasVertices(*run)) {
      vertices.push_back({ToString(run->method) + " AUC " + Number(s.vertex_pck.auc, 3),
                          Mm(s.vertex_pck.thresholds), s.vertex_pck.pck,
                          PlotColor(ColorOf(run->method))});
    }
  }
  PlotOptions o = Plot("3D PCK of keypoints", "error threshold (mm)", "PCK");
  o.y_min = 0;
  o.y_max = 1;
  std::vector<ImageU8> plots = {DrawLinePlot(joints, o)};
  if (!vertices.empty()) {
    o.title = "3D PCK of vertices";
    plots.push_back(DrawLinePlot(vertices, o));
  }
  return StackVertically(plots);
}

ImageU8 PerJointPicture(const CompareResult& r) {
  std::vector<PlotSeries> bars;
  for (const MethodRun* run : Scored(r)) {
    const Eigen::VectorXd mean = 1000 * run->scores.joint_errors.colwise().mean();
    bars.push_back({ToString(run->method),
                    {},
                    std::vector<double>(mean.data(), mean.data() + mean.size()),
                    PlotColor(ColorOf(run->method))});
  }
  PlotOptions o = Plot(
      "mean error per keypoint",
      "keypoint (SNAP order: 0 wrist, 4 thumb tip, 8 index tip, 12 middle tip, 16 ring "
      "tip, 20 little tip)",
      "mm");
  o.width = 1000;
  return DrawBarPlot(bars, o);
}

ImageU8 HistogramPicture(const CompareResult& r) {
  double hi = 0;
  for (const MethodRun* run : Scored(r))
    for (const HandFrameMetrics& m : run->scores.per_frame)
      hi = std::max(hi, 1000 * m.mpjpe);
  hi = std::max(1.0, std::ceil(hi));
  const int bins = 20;
  std::vector<PlotSeries> series;
  for (const MethodRun* run : Scored(r)) {
    std::vector<double> errors;
    for (const HandFrameMetrics& m : run->scores.per_frame)
      errors.push_back(1000 * m.mpjpe);
    const std::vector<int> counts = HistogramCounts(errors, 0, hi, bins);
    PlotSeries s{ToString(run->method), {}, {}, PlotColor(ColorOf(run->method))};
    s.marker_radius = 2;
    for (int b = 0; b < bins; ++b) {
      s.x.push_back((b + 0.5) * hi / bins);
      s.y.push_back(double(counts[b]) / errors.size());
    }
    series.push_back(std::move(s));
  }
  PlotOptions o =
      Plot("per-frame MPJPE histogram (20 bins)", "MPJPE (mm)", "share of frames");
  o.x_min = 0;
  o.x_max = hi;
  o.y_min = 0;
  return DrawLinePlot(series, o);
}

ImageU8 TimeAccuracyPicture(const CompareResult& r) {
  std::vector<PlotSeries> series;
  for (const MethodRun* run : Scored(r)) {
    PlotSeries s{ToString(run->method),
                 {run->seconds_per_frame},
                 {1000 * run->scores.mean.mpjpe},
                 PlotColor(ColorOf(run->method))};
    s.lines = false;
    s.marker_radius = 5;
    series.push_back(std::move(s));
  }
  PlotOptions o =
      Plot("time vs accuracy", "seconds per frame (summed over threads)", "MPJPE (mm)");
  o.x_min = 0;
  o.y_min = 0;
  double x_max = 0, y_max = 0;
  for (const PlotSeries& s : series) {
    x_max = std::max(x_max, s.x[0]);
    y_max = std::max(y_max, s.y[0]);
  }
  o.x_max = std::max(1e-3, 1.15 * x_max);
  o.y_max = std::max(1e-3, 1.15 * y_max);
  return DrawLinePlot(series, o);
}

ImageU8 AblationPicture(const CompareResult& r) {
  std::map<CompareMethod, PlotSeries> by_method;
  for (const AblationCell& c : r.ablation) {
    if (!c.why_not.empty() || c.frames == 0) continue;
    PlotSeries& s = by_method[c.method];
    s.name = ToString(c.method);
    s.color = PlotColor(ColorOf(c.method));
    s.marker_radius = 3;
    s.x.push_back(c.views);
    s.y.push_back(c.mpjpe_mm);
  }
  std::vector<PlotSeries> series;
  for (auto& [m, s] : by_method) {
    std::vector<size_t> order(s.x.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return s.x[a] < s.x[b]; });
    PlotSeries sorted = s;
    for (size_t i = 0; i < order.size(); ++i) {
      sorted.x[i] = s.x[order[i]];
      sorted.y[i] = s.y[order[i]];
    }
    series.push_back(sorted);
  }
  PlotOptions o = Plot("view-count ablation", "views with 2D evidence", "MPJPE (mm)");
  o.y_min = 0;
  return DrawLinePlot(series, o);
}

PlotSeries Line(const std::string& name, std::vector<double> x, std::vector<double> y,
                int color) {
  return {name, std::move(x), std::move(y), PlotColor(color)};
}

ImageU8 QaScatterPicture(const QualityStudy& qa) {
  std::vector<ImageU8> plots;
  for (const CheckStudy& c : qa.checks) {
    double x_max = std::max(c.current, c.chosen), y_max = qa.error_mm;
    PlotSeries points{"network answers", {}, {}, PlotColor(0)};
    points.lines = false;
    points.marker_radius = 3;
    for (size_t i = 0; i < c.values.size(); ++i) {
      if (!std::isfinite(c.values[i])) continue;
      points.x.push_back(c.values[i]);
      points.y.push_back(c.errors_mm[i]);
      x_max = std::max(x_max, c.values[i]);
      y_max = std::max(y_max, c.errors_mm[i]);
    }
    x_max *= 1.05;
    y_max *= 1.05;
    PlotOptions o =
        Plot(c.name + ": value vs MPJPE", c.name + " (" + c.unit + ")", "MPJPE (mm)");
    o.x_min = 0;
    o.x_max = x_max;
    o.y_min = 0;
    o.y_max = y_max;
    plots.push_back(DrawLinePlot({points,
                                  Line("current threshold " + Number(c.current, 1),
                                       {c.current, c.current}, {0, y_max}, 3),
                                  Line("chosen threshold " + Number(c.chosen, 1),
                                       {c.chosen, c.chosen}, {0, y_max}, 2),
                                  Line("error " + Number(qa.error_mm, 0) + " mm",
                                       {0, x_max}, {qa.error_mm, qa.error_mm}, 7)},
                                 o));
  }
  return StackVertically(plots);
}

ImageU8 QaRocPicture(const QualityStudy& qa) {
  std::vector<PlotSeries> series;
  int color = 0;
  for (const CheckStudy& c : qa.checks) {
    PlotSeries curve{
        c.name + " (AUC " + Number(c.roc_auc, 2) + ")", {}, {}, PlotColor(color)};
    for (const RocPoint& p : c.roc) {
      curve.x.push_back(p.false_positive_rate);
      curve.y.push_back(p.true_positive_rate);
    }
    series.push_back(curve);
    PlotSeries current{c.name + " current",
                       {c.at_current.false_positive_rate},
                       {c.at_current.true_positive_rate},
                       PlotColor(color)};
    current.lines = false;
    current.marker_radius = 6;
    PlotSeries chosen{c.name + " chosen",
                      {c.at_chosen.false_positive_rate},
                      {c.at_chosen.true_positive_rate},
                      PlotColor(color + 3)};
    chosen.lines = false;
    chosen.marker_radius = 4;
    series.push_back(current);
    series.push_back(chosen);
    ++color;
  }
  PlotOptions o =
      Plot("ROC: check flags answers with MPJPE > " + Number(qa.error_mm, 0) + " mm",
           "false-positive rate", "true-positive rate");
  o.x_min = o.y_min = 0;
  o.x_max = o.y_max = 1;
  return DrawLinePlot(series, o);
}

// ---- worst frames ----

// The square around the true keypoints in view v (1.6 x their box), or an empty
// box when some keypoint does not project into the image.
struct Box {
  int x0 = 0, y0 = 0, side = 0;
};

Box HandBox(const RigCamera& cam, const Points3d& keypoints) {
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (int k = 0; k < keypoints.rows(); ++k) {
    Eigen::Vector2d uv;
    if (!cam.ProjectWorld(keypoints.row(k).transpose(), &uv)) return {};
    lo = lo.cwiseMin(uv);
    hi = hi.cwiseMax(uv);
  }
  const double side = 1.6 * (hi - lo).maxCoeff() + 8;
  const Eigen::Vector2d c = (lo + hi) / 2;
  Box b{static_cast<int>(c.x() - side / 2), static_cast<int>(c.y() - side / 2),
        static_cast<int>(side)};
  if (b.x0 < 0 || b.y0 < 0 || b.x0 + b.side > cam.camera.width() ||
      b.y0 + b.side > cam.camera.height()) {
    return {};
  }
  return b;
}

// The box of `image`, resized (nearest) to size x size, under a caption band.
ImageU8 Panel(const ImageU8& image, const Box& box, int size,
              const std::string& caption) {
  const int band = 14;
  ImageU8 out(size, size + band, 3, 255);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const int sx = std::clamp(box.x0 + x * box.side / size, 0, image.width - 1);
      const int sy = std::clamp(box.y0 + y * box.side / size, 0, image.height - 1);
      for (int c = 0; c < 3; ++c)
        out.at(x, band + y, c) = image.at(sx, sy, std::min(c, image.channels - 1));
    }
  }
  DrawText(&out, 3, 3, caption, {0, 0, 0});
  return out;
}

ImageU8 ReadRgb(const std::string& path, const RigCamera& cam) {
  try {
    ImageU8 image = ReadImageFile(path);
    if (image.channels == 3) return image;
  } catch (const std::exception&) {
  }
  return ImageU8(cam.camera.width(), cam.camera.height(), 3, 128);
}

std::vector<std::string> WorstFrames(const CompareResult& r, int count) {
  const std::vector<const MethodRun*> runs = Scored(r);
  if (runs.empty() || count == 0) return {};
  const MethodScores& s = runs.front()->scores;
  std::vector<size_t> order(s.frames.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return s.per_frame[a].mpjpe > s.per_frame[b].mpjpe;
  });
  std::vector<std::string> frames;
  for (size_t i = 0; i < order.size() && static_cast<int>(i) < count; ++i)
    frames.push_back(s.frames[order[i]]);
  return frames;
}

// One row per frame: the truth, then every scored method's label, drawn on the view
// where the hand's box is largest.
ImageU8 WorstFramesPicture(const JobConfig& base, const CompareResult& r, int count) {
  const std::vector<std::string> frames = WorstFrames(r, count);
  if (frames.empty()) return {};
  const std::unique_ptr<FrameSource> source = BuildFrameSource(base);
  const ResolvedHandModel hand =
      ResolveHandModel(base.hand_model, source->side(), {base.source_file, "hand_model"});
  const Faces faces = hand.model.faces;
  std::vector<ImageU8> rows;
  for (const std::string& frame : frames) {
    const FrameInput input = source->Load(frame);
    if (!input.ground_truth) continue;
    const FrameGroundTruth& truth = *input.ground_truth;
    int view = -1;
    Box box;
    for (size_t v = 0; v < input.rig.size(); ++v) {
      const Box b = HandBox(input.rig[v], truth.keypoints);
      if (b.side > box.side) {
        box = b;
        view = static_cast<int>(v);
      }
    }
    if (view < 0) continue;
    const RigCamera& cam = input.rig[view];
    const ImageU8 image = ReadRgb(input.image_paths[view], cam);
    std::vector<ImageU8> panels;
    LabelRecord truth_label;
    truth_label.mesh.keypoints = truth.keypoints;
    truth_label.mesh.vertices = truth.vertices.rows() == hand.model.num_vertices()
                                    ? truth.vertices
                                    : Points3d(0, 3);
    ImageU8 drawn = image;
    DrawLabelOverlay(cam, truth_label, faces, &drawn);
    panels.push_back(Panel(drawn, box, 200, frame + " truth (" + cam.name + ")"));
    for (const MethodRun* run : Scored(r)) {
      const std::optional<LabelRecord> label = MethodLabel(*run, frame);
      if (!label) continue;
      const auto it =
          std::find(run->scores.frames.begin(), run->scores.frames.end(), frame);
      const double mm =
          it == run->scores.frames.end()
              ? kNaN
              : 1000 * run->scores.per_frame[it - run->scores.frames.begin()].mpjpe;
      drawn = image;
      DrawLabelOverlay(cam, *label, faces, &drawn);
      panels.push_back(
          Panel(drawn, box, 200, ToString(run->method) + " " + Number(mm, 1) + " mm"));
    }
    rows.push_back(StackHorizontally(panels, 4));
  }
  return rows.empty() ? ImageU8() : StackVertically(rows);
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
      row.push_back({Number(values.at(c.key), c.decimals),
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
          cell = {Number(c.mpjpe_mm, 2), "ablation." + std::to_string(i) + ".mpjpe_mm",
                  2};
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
                      {Number(c.current, 2), p + "current", 2},
                      {Number(c.chosen, 2), p + "chosen", 2},
                      {Number(c.roc_auc, 3), p + "roc_auc", 3},
                      {Number(c.precision_current, 3), p + "precision_current", 3},
                      {Number(c.recall_current, 3), p + "recall_current", 3},
                      {Number(c.precision_chosen, 3), p + "precision_chosen", 3},
                      {Number(c.recall_chosen, 3), p + "recall_chosen", 3}});
  }
  return t;
}

HtmlTable QaShareTable(const QualityStudy& qa) {
  HtmlTable t;
  t.id = "qa_share";
  t.header = {"thresholds", "kept answers", "kept of all",
              "kept with MPJPE > " + Number(qa.error_mm, 0) + " mm", "share"};
  auto row = [](const char* name, const KeptShare& s, const std::string& key) {
    return std::vector<HtmlCell>{
        {name},
        {std::to_string(s.kept), "qa." + key + ".kept", 0},
        {Number(s.KeptFraction(), 3), "qa." + key + ".kept_fraction", 3},
        {std::to_string(s.kept_bad), "qa." + key + ".kept_bad", 0},
        {Number(s.Share(), 3), "qa." + key + ".share", 3}};
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
      Number(r.auc_max_mm, 0) + " mm\n";
  for (const MethodRun& run : r.methods) {
    text += ToString(run.method) + ": " +
            (Ran(run) ? run.evidence + ", labels in " + run.output_dir
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
                      {"ran", Ran(run)},
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
  m["pck_thresholds_mm"] = Mm(run.scores.joint_pck.thresholds);
  m["joint_pck"] = run.scores.joint_pck.pck;
  if (HasVertices(run)) m["vertex_pck"] = run.scores.vertex_pck.pck;
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
      "over 0-" + Number(r.auc_max_mm, 0) +
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
  if (!Scored(r).empty()) {
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
                             Number(qa.error_mm, 0) +
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
