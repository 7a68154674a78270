#include "pipeline/frame_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "formats/sha256.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace {

FrameRecord ParseRecord(const std::string& line, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source, "record", "one JSON object per line", e.what());
  }
  FrameRecord r;
  try {
    r.frame = j.at("frame").get<std::string>();
    r.status = j.at("status").get<std::string>();
    r.path = j.value("path", "");
    r.reason = j.value("reason", "");
    r.seconds = j.value("seconds", 0.0);
    r.label_bytes = j.value("label_bytes", int64_t{-1});
    r.label_sha256 = j.value("label_sha256", "");
    r.job_hash = j.value("job_hash", "");
    r.crops = j.value("crops", "");
    r.hand = j.value("hand", "");
    if (j.contains("metrics")) {
      for (const auto& [name, value] : j.at("metrics").items()) {
        r.metrics[name] = value.is_null() ? std::nan("") : value.get<double>();
      }
    }
    if (j.contains("stages"))
      r.stages = j.at("stages").get<std::map<std::string, double>>();
    if (j.contains("keypoints_mm")) {
      r.keypoints_mm =
          j.at("keypoints_mm").get<std::map<std::string, std::vector<double>>>();
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source, "record", "fields frame and status", e.what());
  }
  if (r.status != "ok" && r.status != "failed") {
    throw InputError(source, "status", "'ok' or 'failed'", "'" + r.status + "'");
  }
  return r;
}

}  // namespace

std::string LabelFileProblem(const FrameRecord& record, const std::string& label_path) {
  std::error_code error;
  const uintmax_t bytes = std::filesystem::file_size(label_path, error);
  if (error) return "label file " + label_path + " is missing";
  if (record.label_sha256.empty()) {
    try {
      ReadLabelFile(label_path);
    } catch (const std::exception& e) {
      return "label file " + label_path + " is unreadable: " + e.what();
    }
    return "";
  }
  if (static_cast<int64_t>(bytes) != record.label_bytes) {
    return "label file " + label_path + " has " + std::to_string(bytes) +
           " bytes, the log recorded " + std::to_string(record.label_bytes) +
           " (truncated or replaced)";
  }
  if (Sha256OfFile(label_path) != record.label_sha256) {
    return "label file " + label_path +
           " does not match the SHA-256 the log recorded (changed after it was written)";
  }
  return "";
}

std::vector<FrameRecord> FrameLog::Read(const std::string& path) {
  std::vector<FrameRecord> records;
  std::ifstream in(path, std::ios::binary);
  if (!in) return records;
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  size_t start = 0;
  int line_number = 0;
  while (start < text.size()) {
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) break;  // partial last line from a crash: ignore
    ++line_number;
    const std::string line = text.substr(start, end - start);
    if (!line.empty()) {
      records.push_back(ParseRecord(line, path + ":" + std::to_string(line_number)));
    }
    start = end + 1;
  }
  return records;
}

FrameLog::FrameLog(std::string path) : path_(std::move(path)) {
  for (FrameRecord& r : Read(path_)) latest_[r.frame] = std::move(r);
  // Cut a partial last line left by a crash: appending after it would glue the next
  // record onto it and turn it into a malformed complete line.
  std::ifstream in(path_, std::ios::binary);
  if (!in) return;
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const size_t keep = text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1;
  if (keep < text.size()) std::filesystem::resize_file(path_, keep);
}

bool FrameLog::IsDone(const std::string& frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = latest_.find(frame);
  return it != latest_.end() && it->second.status == "ok";
}

void FrameLog::Record(const FrameRecord& record) {
  nlohmann::json j = {{"frame", record.frame},
                      {"status", record.status},
                      {"path", record.path},
                      {"seconds", record.seconds}};
  if (!record.stages.empty()) j["stages"] = record.stages;
  if (!record.reason.empty()) j["reason"] = record.reason;
  if (!record.metrics.empty()) j["metrics"] = record.metrics;
  if (!record.keypoints_mm.empty()) j["keypoints_mm"] = record.keypoints_mm;
  if (record.label_bytes >= 0) j["label_bytes"] = record.label_bytes;
  if (!record.label_sha256.empty()) j["label_sha256"] = record.label_sha256;
  if (!record.job_hash.empty()) j["job_hash"] = record.job_hash;
  if (!record.crops.empty()) j["crops"] = record.crops;
  if (!record.hand.empty()) j["hand"] = record.hand;
  std::lock_guard<std::mutex> lock(mutex_);
  AppendLineDurably(path_, j.dump());
  latest_[record.frame] = record;
}

std::vector<FrameRecord> FrameLog::Latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<FrameRecord> out;
  for (const auto& [frame, record] : latest_) out.push_back(record);
  return out;
}

}  // namespace handlabel
