// The pictures of `handlabel compare` (compare_report.h): PCK curves, per-joint
// errors, histograms, time vs accuracy, the view ablation, the quality-check study and
// the worst frames with every method's overlay.
#include "comparison/compare_pictures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "image/draw.h"
#include "image/line_plot.h"
#include "image/rasterizer.h"
#include "image/view_image.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/label_overlay.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {

std::string FormatFixed(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

std::vector<double> Millimetres(std::vector<double> metres) {
  for (double& x : metres) x *= 1000;
  return metres;
}

std::vector<const MethodRun*> ScoredMethods(const CompareResult& r) {
  std::vector<const MethodRun*> runs;
  for (const MethodRun& run : r.methods) {
    if (MethodRan(run) && run.has_truth) runs.push_back(&run);
  }
  return runs;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

PlotOptions Plot(const std::string& title, const std::string& x, const std::string& y) {
  PlotOptions o;
  o.width = 720;
  o.height = 400;
  o.title = title;
  o.x_label = x;
  o.y_label = y;
  return o;
}

int ColorOf(CompareMethod m) { return static_cast<int>(m); }

}  // namespace

ImageU8 PckPicture(const CompareResult& r) {
  std::vector<PlotSeries> joints, vertices;
  for (const MethodRun* run : ScoredMethods(r)) {
    const MethodScores& s = run->scores;
    joints.push_back({ToString(run->method) + " AUC " + FormatFixed(s.joint_pck.auc, 3),
                      Millimetres(s.joint_pck.thresholds), s.joint_pck.pck,
                      PlotColor(ColorOf(run->method))});
    if (MethodHasVertices(*run)) {
      vertices.push_back(
          {ToString(run->method) + " AUC " + FormatFixed(s.vertex_pck.auc, 3),
           Millimetres(s.vertex_pck.thresholds), s.vertex_pck.pck,
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
  for (const MethodRun* run : ScoredMethods(r)) {
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
  for (const MethodRun* run : ScoredMethods(r))
    for (const HandFrameMetrics& m : run->scores.per_frame)
      hi = std::max(hi, 1000 * m.mpjpe);
  hi = std::max(1.0, std::ceil(hi));
  const int bins = 20;
  std::vector<PlotSeries> series;
  for (const MethodRun* run : ScoredMethods(r)) {
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
  for (const MethodRun* run : ScoredMethods(r)) {
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

namespace {

PlotSeries Line(const std::string& name, std::vector<double> x, std::vector<double> y,
                int color) {
  return {name, std::move(x), std::move(y), PlotColor(color)};
}

}  // namespace

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
                                  Line("current threshold " + FormatFixed(c.current, 1),
                                       {c.current, c.current}, {0, y_max}, 3),
                                  Line("chosen threshold " + FormatFixed(c.chosen, 1),
                                       {c.chosen, c.chosen}, {0, y_max}, 2),
                                  Line("error " + FormatFixed(qa.error_mm, 0) + " mm",
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
        c.name + " (AUC " + FormatFixed(c.roc_auc, 2) + ")", {}, {}, PlotColor(color)};
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
      Plot("ROC: check flags answers with MPJPE > " + FormatFixed(qa.error_mm, 0) + " mm",
           "false-positive rate", "true-positive rate");
  o.x_min = o.y_min = 0;
  o.x_max = o.y_max = 1;
  return DrawLinePlot(series, o);
}

namespace {

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

// A picture is no reason to fail the comparison: an unreadable view is shown grey.
ImageU8 ReadRgb(const std::string& path, const RigCamera& cam) {
  try {
    return ReadViewImageRgb(path, cam);
  } catch (const std::exception&) {
    return ImageU8(cam.camera.width(), cam.camera.height(), 3, 128);
  }
}

std::vector<std::string> WorstFrames(const CompareResult& r, int count) {
  const std::vector<const MethodRun*> runs = ScoredMethods(r);
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

}  // namespace

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
    const PixelRays rays(cam.camera);
    std::vector<ImageU8> panels;
    LabelRecord truth_label;
    truth_label.mesh.keypoints = truth.keypoints;
    truth_label.mesh.vertices = truth.vertices.rows() == hand.model.num_vertices()
                                    ? truth.vertices
                                    : Points3d(0, 3);
    ImageU8 drawn = image;
    DrawLabelOverlay(cam, rays, truth_label, faces, &drawn);
    panels.push_back(Panel(drawn, box, 200, frame + " truth (" + cam.name + ")"));
    for (const MethodRun* run : ScoredMethods(r)) {
      const std::optional<LabelRecord> label = MethodLabel(*run, frame);
      if (!label) continue;
      const auto it =
          std::find(run->scores.frames.begin(), run->scores.frames.end(), frame);
      const double mm =
          it == run->scores.frames.end()
              ? kNaN
              : 1000 * run->scores.per_frame[it - run->scores.frames.begin()].mpjpe;
      drawn = image;
      DrawLabelOverlay(cam, rays, *label, faces, &drawn);
      panels.push_back(Panel(drawn, box, 200,
                             ToString(run->method) + " " + FormatFixed(mm, 1) + " mm"));
    }
    rows.push_back(StackHorizontally(panels, 4));
  }
  return rows.empty() ? ImageU8() : StackVertically(rows);
}

}  // namespace handlabel
