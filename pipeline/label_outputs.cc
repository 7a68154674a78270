#include "pipeline/label_outputs.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

std::string ShardStem(const std::string& output_dir, const ShardSpec& shard) {
  char name[64];
  std::snprintf(name, sizeof(name), "shard-%05d-of-%05d", shard.index, shard.count);
  return output_dir + "/shards/" + name;
}

// "name.ext.tmp.<pid>" -> "name.ext"; "" if not a temporary.
std::string TemporaryTarget(const std::string& file_name) {
  const size_t at = file_name.rfind(".tmp.");
  return at == std::string::npos ? "" : file_name.substr(0, at);
}

// What the shards' summaries say the 2D keypoints were (every shard of a job has the
// same); "" when no shard has written its summary yet.
std::string KeypointsSourceOfShards(const std::string& output_dir) {
  const fs::path shards = fs::path(output_dir) / "shards";
  if (!fs::is_directory(shards)) return "";
  for (const auto& entry : fs::directory_iterator(shards)) {
    const std::string name = entry.path().filename().string();
    const std::string suffix = ".summary.json";
    if (name.size() <= suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    std::ifstream in(entry.path());
    const nlohmann::json j =
        nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (j.is_object() && j.value("keypoints_2d_source", "") != "") {
      return j["keypoints_2d_source"].get<std::string>();
    }
  }
  return "";
}

}  // namespace

std::string ShardLogPath(const std::string& output_dir, const ShardSpec& shard) {
  return ShardStem(output_dir, shard) + ".jsonl";
}
std::string ShardSummaryPath(const std::string& output_dir, const ShardSpec& shard) {
  return ShardStem(output_dir, shard) + ".summary.json";
}
std::string JobStampPath(const std::string& output_dir) {
  return output_dir + "/job.json";
}
std::string ManifestPath(const std::string& output_dir) {
  return output_dir + "/manifest.json";
}
std::string SummaryJsonPath(const std::string& output_dir) {
  return output_dir + "/summary.json";
}
std::string SummaryMarkdownPath(const std::string& output_dir) {
  return output_dir + "/summary.md";
}
std::string OverlayPath(const std::string& output_dir, const std::string& frame,
                        const std::string& camera, const std::string& format) {
  return output_dir + "/overlays/" + FrameFileStem(frame, "frame id") + "/" +
         FrameFileStem(camera, "camera name") + "." + format;
}

std::string JobDetectionsDir(const std::string& output_dir) {
  return output_dir + "/detections";
}

std::string JobDetectionsPath(const std::string& output_dir, const std::string& frame) {
  return JobDetectionsDir(output_dir) + "/" + FrameFileStem(frame, "frame id") + ".json";
}

std::map<std::string, FrameRecord> ReadShardLogs(const std::string& output_dir) {
  std::map<std::string, FrameRecord> latest;
  const fs::path dir = fs::path(output_dir) / "shards";
  if (!fs::is_directory(dir)) return latest;
  std::vector<fs::path> logs;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".jsonl") logs.push_back(entry.path());
  }
  std::sort(logs.begin(), logs.end());  // deterministic when logs disagree
  for (const fs::path& log : logs) {
    for (FrameRecord& r : FrameLog::Read(log.string())) {
      auto it = latest.find(r.frame);
      if (it == latest.end() || r.status == "ok" || it->second.status != "ok") {
        latest[r.frame] = std::move(r);
      }
    }
  }
  return latest;
}

void CheckOutputsBelongToJob(const std::string& output_dir, const std::string& job_hash) {
  const std::string stamp = JobStampPath(output_dir);
  if (fs::exists(stamp)) {
    std::string recorded;
    try {
      std::ifstream in(stamp);
      recorded = nlohmann::json::parse(in).at("job_hash").get<std::string>();
    } catch (const std::exception& e) {
      throw InputError(stamp, "job_hash", "a job stamp written by handlabel", e.what());
    }
    if (recorded != job_hash) {
      throw InputError(
          stamp, "job_hash",
          "this job's hash " + job_hash +
              " (the folder holds the outputs of another job or job version)",
          recorded);
    }
  }
  const fs::path dir = fs::path(output_dir) / "shards";
  if (!fs::is_directory(dir)) return;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".jsonl") continue;
    for (const FrameRecord& r : FrameLog::Read(entry.path().string())) {
      if (!r.job_hash.empty() && r.job_hash != job_hash) {
        throw InputError(entry.path().string(), "job_hash",
                         "records of this job (hash " + job_hash + ")",
                         "frame '" + r.frame + "' of job " + r.job_hash);
      }
    }
  }
}

LabelSummary MergeLabelOutputs(const std::string& output_dir, const std::string& job_name,
                               const std::string& job_hash,
                               const std::vector<std::string>& frames,
                               const std::string& keypoints_2d_source,
                               std::vector<std::string>* not_labelled,
                               const LabelSummary* run) {
  CheckOutputsBelongToJob(output_dir, job_hash);  // before anything is written
  std::map<std::string, FrameRecord> records = ReadShardLogs(output_dir);
  nlohmann::json entries = nlohmann::json::array();
  for (const std::string& frame : frames) {
    auto it = records.find(frame);
    nlohmann::json entry = {{"frame", frame}};
    const std::string label = "labels/" + FrameFileStem(frame, "frame id") + ".json";
    std::string problem;
    if (it != records.end() && it->second.status == "ok") {
      problem = LabelFileProblem(it->second, output_dir + "/" + label);
    }
    if (!problem.empty()) {
      records.erase(it);  // logged but the file is gone or damaged: label it again
      it = records.end();
    }
    if (it == records.end()) {
      entry["status"] = "missing";
      if (!problem.empty()) entry["reason"] = problem;
      if (not_labelled) {
        not_labelled->push_back(
            frame + (problem.empty() ? " (not yet run)" : " (" + problem + ")"));
      }
    } else if (it->second.status == "ok") {
      entry["status"] = "ok";
      entry["path"] = it->second.path;
      entry["label"] = label;
    } else {
      entry["status"] = "failed";
      entry["reason"] = it->second.reason;
    }
    entries.push_back(entry);
  }
  LabelSummary summary = Summarize(frames, records);
  summary.keypoints_2d_source = keypoints_2d_source.empty()
                                    ? KeypointsSourceOfShards(output_dir)
                                    : keypoints_2d_source;
  if (run) {
    summary.wall_seconds = run->wall_seconds;
    summary.threads = run->threads;
    summary.skipped = run->skipped;
  }
  const nlohmann::json manifest = {{"format", "handlabel-manifest"},
                                   {"format_version", 1},
                                   {"job", job_name},
                                   {"job_hash", job_hash},
                                   {"frames", entries},
                                   {"counts",
                                    {{"frames", summary.frames},
                                     {"ok", summary.ok},
                                     {"failed", summary.failed},
                                     {"missing", summary.missing},
                                     {"by_path", summary.by_path}}}};
  WriteFileAtomically(ManifestPath(output_dir), manifest.dump(1) + "\n");
  WriteFileAtomically(SummaryJsonPath(output_dir), summary.ToJson().dump(1) + "\n");
  WriteFileAtomically(SummaryMarkdownPath(output_dir),
                      "# Labeling job " + job_name + "\n\n" + summary.ToMarkdown());
  return summary;
}

int RemoveStaleFrameTemporaries(const std::string& output_dir,
                                const std::vector<std::string>& frames) {
  std::set<std::string> stems;
  for (const std::string& f : frames) stems.insert(FrameFileStem(f, "frame id"));
  int removed = 0;
  for (const char* sub : {"labels", "meshes", "overlays"}) {
    const fs::path dir = fs::path(output_dir) / sub;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (!entry.is_regular_file()) continue;
      const std::string target = TemporaryTarget(entry.path().filename().string());
      if (target.empty()) continue;
      // labels/<stem>.json, meshes/<stem>.<ext>, overlays/<stem>/<camera>.<jpg|png>
      const std::string stem = std::string(sub) == "overlays"
                                   ? entry.path().parent_path().filename().string()
                                   : fs::path(target).stem().string();
      if (stems.count(stem)) {
        fs::remove(entry.path());
        ++removed;
      }
    }
  }
  return removed;
}

}  // namespace handlabel
