#include "pipeline/label_summary.h"

#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>

#include "hand/metrics.h"
#include "pipeline/frame_metrics.h"

namespace handlabel {
namespace {

// Groups in report order, then metrics in report order.
const std::vector<std::string> kGroupOrder = {"labels",       "network",     "refined",
                                              "fallback_fit", "network_raw", "fit_only"};
const std::vector<std::pair<std::string, std::string>> kMetricColumns = {
    {"mpjpe_mm", "MPJPE mm"},       {"pa_mpjpe_mm", "PA-MPJPE mm"},
    {"mpvpe_mm", "MPVPE mm"},       {"pa_mpvpe_mm", "PA-MPVPE mm"},
    {"auc", "AUC 0-20mm"},          {"accel_error_mm", "accel. error mm/f^2"},
    {"jitter_mm", "jitter mm/f^2"},
};

std::string Number(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

std::vector<std::string> GroupsInOrder(
    const std::map<std::string, std::map<std::string, MetricMean>>& metrics) {
  std::vector<std::string> groups;
  for (const std::string& g : kGroupOrder) {
    if (metrics.count(g)) groups.push_back(g);
  }
  for (const auto& [g, unused] : metrics) {
    if (std::find(kGroupOrder.begin(), kGroupOrder.end(), g) == kGroupOrder.end()) {
      groups.push_back(g);
    }
  }
  return groups;
}

int GroupFrames(const std::map<std::string, MetricMean>& metrics) {
  const auto it = metrics.find("mpjpe_mm");
  return it == metrics.end() ? 0 : it->second.count;
}

// The motion metrics of every group with keypoints in the records, over the triples of
// consecutive frames of `frames` (capture order) that all have the group's keypoints;
// as means over those triples.
void AddMotionMetrics(const std::vector<std::string>& frames,
                      const std::map<std::string, FrameRecord>& records,
                      LabelSummary* summary) {
  std::set<std::string> groups;
  for (const auto& [frame, record] : records) {
    for (const auto& [group, unused] : record.keypoints_mm) groups.insert(group);
  }
  groups.erase(kTruthKeypoints);
  const std::vector<int64_t> numbers = MotionFrameNumbers(frames);
  for (const std::string& group : groups) {
    std::vector<MotionFrame> motion;
    for (size_t i = 0; i < frames.size(); ++i) {
      const auto it = records.find(frames[i]);
      if (it == records.end() || it->second.status != "ok") continue;
      const auto& keypoints = it->second.keypoints_mm;
      if (!keypoints.count(group) || !keypoints.count(kTruthKeypoints)) continue;
      motion.push_back({numbers[i], KeypointsFromMillimetres(keypoints.at(group)),
                        KeypointsFromMillimetres(keypoints.at(kTruthKeypoints))});
    }
    const MotionMetrics m = ComputeMotionMetrics(motion);
    if (m.triples == 0) continue;
    auto& means = summary->metrics[group];
    means["accel_error_mm"] = {1000 * m.acceleration_error * m.triples, m.triples};
    means["jitter_mm"] = {1000 * m.jitter * m.triples, m.triples};
  }
}

// Stages grouped by the name before the first dot: group -> (its total, its parts).
struct StageGroup {
  std::string name;
  double seconds = 0;
  std::vector<std::pair<std::string, double>> parts;  // "palm" of "detect.palm"
};

std::vector<StageGroup> GroupStages(const std::map<std::string, double>& stages) {
  std::map<std::string, StageGroup> groups;
  for (const auto& [stage, seconds] : stages) {
    const size_t dot = stage.find('.');
    StageGroup& g = groups[stage.substr(0, dot)];
    g.name = stage.substr(0, dot);
    g.seconds += seconds;
    if (dot != std::string::npos) g.parts.emplace_back(stage.substr(dot + 1), seconds);
  }
  const auto longest_first = [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first < b.first;
  };
  std::vector<StageGroup> out;
  for (auto& [name, g] : groups) {
    std::sort(g.parts.begin(), g.parts.end(), longest_first);
    out.push_back(std::move(g));
  }
  std::sort(out.begin(), out.end(), [](const StageGroup& a, const StageGroup& b) {
    return a.seconds != b.seconds ? a.seconds > b.seconds : a.name < b.name;
  });
  return out;
}

std::string StageRow(const std::string& name, double seconds, double total, int frames) {
  char row[128];
  std::snprintf(row, sizeof(row), "  %-22s %9.2f %6.1f %% %9.1f\n", name.c_str(), seconds,
                total > 0 ? 100 * seconds / total : 0.0,
                frames > 0 ? 1000 * seconds / frames : 0.0);
  return row;
}

}  // namespace

std::string LabelSummary::StageTable() const {
  if (stage_frames == 0) return "";
  double total = 0;
  for (const auto& [stage, seconds] : stage_seconds) total += seconds;
  std::ostringstream out;
  out << "where the time went (" << stage_frames << " frames; seconds inside each stage "
      << "summed over frames, " << Number(total, 1) << " s in all";
  // Only a run that labelled every frame it reports compares with its wall time.
  if (wall_seconds > 0 && threads > 0 && skipped == 0) {
    out << "; " << threads << " thread(s) x " << Number(wall_seconds, 1)
        << " s wall: stages busy " << Number(100 * total / (threads * wall_seconds), 0)
        << " %";
  }
  out << "):\n";
  char head[128];
  std::snprintf(head, sizeof(head), "  %-22s %9s %8s %9s\n", "stage", "seconds", "share",
                "ms/frame");
  out << head;
  for (const StageGroup& g : GroupStages(stage_seconds)) {
    out << StageRow(g.name, g.seconds, total, stage_frames);
    // Parts under 0.1 % of all stages in one row when there are several (JSON: each).
    size_t shown = g.parts.size();
    while (shown > 0 && g.parts[shown - 1].second < 1e-3 * total) --shown;
    if (g.parts.size() - shown < 2) shown = g.parts.size();
    double rest = 0;
    for (size_t k = 0; k < g.parts.size(); ++k) {
      if (k < shown) {
        out << StageRow("  ." + g.parts[k].first, g.parts[k].second, total, stage_frames);
      } else {
        rest += g.parts[k].second;
      }
    }
    if (shown < g.parts.size()) {
      out << StageRow("  (" + std::to_string(g.parts.size() - shown) + " more)", rest,
                      total, stage_frames);
    }
  }
  return out.str();
}

LabelSummary Summarize(const std::vector<std::string>& frames,
                       const std::map<std::string, FrameRecord>& records) {
  LabelSummary s;
  s.frames = static_cast<int>(frames.size());
  for (const std::string& frame : frames) {
    const auto it = records.find(frame);
    if (it == records.end()) {
      ++s.missing;
      continue;
    }
    const FrameRecord& r = it->second;
    s.frame_seconds += r.seconds;
    for (const auto& [stage, seconds] : r.stages) s.stage_seconds[stage] += seconds;
    s.stage_frames += r.stages.empty() ? 0 : 1;
    if (r.status == "ok") {
      ++s.ok;
      ++s.by_path[r.path];
      if (!r.crops.empty()) ++s.by_crops[r.crops];
    } else {
      ++s.failed;
      s.failures.emplace_back(frame, r.reason);
    }
    for (const auto& [key, value] : r.metrics) {
      const size_t slash = key.find('/');
      if (slash == std::string::npos) continue;
      MetricMean& m = s.metrics[key.substr(0, slash)][key.substr(slash + 1)];
      m.sum += value;
      ++m.count;
    }
  }
  AddMotionMetrics(frames, records, &s);
  return s;
}

nlohmann::json LabelSummary::ToJson() const {
  nlohmann::json j = {{"frames", frames},
                      {"ok", ok},
                      {"failed", failed},
                      {"missing", missing},
                      {"skipped", skipped},
                      {"by_path", by_path},
                      {"frame_seconds", frame_seconds}};
  if (!by_crops.empty()) j["by_crops"] = by_crops;
  // A merge does not know a wall time (shards may run anywhere): no field then.
  if (wall_seconds > 0) j["wall_seconds"] = wall_seconds;
  if (threads > 0) j["threads"] = threads;
  if (stage_frames > 0) {
    j["stage_seconds"] = stage_seconds;
    j["stage_frames"] = stage_frames;
  }
  nlohmann::json fails = nlohmann::json::array();
  for (const auto& [frame, reason] : failures)
    fails.push_back({{"frame", frame}, {"reason", reason}});
  j["failures"] = fails;
  if (!keypoints_2d_source.empty()) j["keypoints_2d_source"] = keypoints_2d_source;
  nlohmann::json groups = nlohmann::json::object();
  for (const auto& [group, metrics] : this->metrics) {
    nlohmann::json g = {{"frames", GroupFrames(metrics)}};
    for (const auto& [name, mean] : metrics) g[name] = mean.Mean();
    groups[group] = g;
  }
  j["metrics"] = groups;
  return j;
}

std::string LabelSummary::ToText() const {
  std::ostringstream out;
  out << frames << " frames: " << ok << " labelled";
  for (const auto& [path, count] : by_path) out << " (" << path << " " << count << ")";
  out << ", " << failed << " failed";
  if (!by_crops.empty()) {
    out << "; network crops:";
    for (const auto& [from, count] : by_crops) out << " " << from << " " << count;
  }
  if (missing > 0) out << ", " << missing << " not yet run";
  if (skipped > 0) out << ", " << skipped << " skipped (done before)";
  out << "\n";
  if (!keypoints_2d_source.empty())
    out << "2D keypoints: " << keypoints_2d_source << "\n";
  if (wall_seconds > 0) {
    out << "time: " << Number(wall_seconds, 1) << " s wall, " << Number(frame_seconds, 1)
        << " s summed over frames\n";
  } else {
    out << "time: " << Number(frame_seconds, 1) << " s summed over frames\n";
  }
  out << StageTable();
  const size_t shown = std::min<size_t>(failures.size(), 10);
  for (size_t i = 0; i < shown; ++i) {
    out << "  failed " << failures[i].first << ": " << failures[i].second << "\n";
  }
  if (failures.size() > shown)
    out << "  ... and " << failures.size() - shown << " more\n";
  for (const std::string& group : GroupsInOrder(metrics)) {
    const auto& m = metrics.at(group);
    out << "  " << group << " (" << GroupFrames(m) << " frames):";
    for (const auto& [key, title] : kMetricColumns) {
      if (m.count(key))
        out << " " << title << " " << Number(m.at(key).Mean(), key == "auc" ? 3 : 2);
    }
    out << "\n";
  }
  return out.str();
}

std::string LabelSummary::ToMarkdown() const {
  std::ostringstream out;
  out << "| frames | labelled | failed | not run | frame time (s) "
         "|\n|---|---|---|---|---|\n"
      << "| " << frames << " | " << ok << " | " << failed << " | " << missing << " | "
      << Number(frame_seconds, 1) << " |\n\n";
  if (!keypoints_2d_source.empty())
    out << "2D keypoints: " << keypoints_2d_source << "\n\n";
  if (!by_path.empty()) {
    out << "| path | frames |\n|---|---|\n";
    for (const auto& [path, count] : by_path)
      out << "| " << path << " | " << count << " |\n";
    out << "\n";
  }
  if (!by_crops.empty()) {
    out << "| network crops from | frames |\n|---|---|\n";
    for (const auto& [from, count] : by_crops)
      out << "| " << from << " | " << count << " |\n";
    out << "\n";
  }
  if (!metrics.empty()) {
    out << "| group | frames |";
    for (const auto& [key, title] : kMetricColumns) out << " " << title << " |";
    out << "\n|---|---|";
    for (size_t i = 0; i < kMetricColumns.size(); ++i) out << "---|";
    out << "\n";
    for (const std::string& group : GroupsInOrder(metrics)) {
      const auto& m = metrics.at(group);
      out << "| " << group << " | " << GroupFrames(m) << " |";
      for (const auto& [key, title] : kMetricColumns) {
        out << " "
            << (m.count(key) ? Number(m.at(key).Mean(), key == "auc" ? 3 : 2) : "-")
            << " |";
      }
      out << "\n";
    }
    out << "\n";
  }
  if (stage_frames > 0) out << "```\n" << StageTable() << "```\n\n";
  if (!failures.empty()) {
    out << "Failed frames:\n\n";
    for (const auto& [frame, reason] : failures)
      out << "- `" << frame << "`: " << reason << "\n";
    out << "\n";
  }
  return out.str();
}

}  // namespace handlabel
