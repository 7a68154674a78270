#include "pipeline/shard.h"

#include <cstdlib>

#include "core/errors.h"

namespace handlabel {
namespace {

bool ParseNonNegative(const std::string& text, int* value) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  *value = std::stoi(text);
  return true;
}

const char* SystemGetenv(const char* name) { return std::getenv(name); }

}  // namespace

ShardSpec ParseShard(const std::string& text, const std::string& source) {
  const size_t slash = text.find('/');
  ShardSpec shard;
  if (slash == std::string::npos ||
      !ParseNonNegative(text.substr(0, slash), &shard.index) ||
      !ParseNonNegative(text.substr(slash + 1), &shard.count) || shard.count < 1 ||
      shard.index >= shard.count) {
    throw InputError(source, "shard", "'i/N' with 0 <= i < N <= 999999999, e.g. 3/16",
                     "'" + text + "'");
  }
  return shard;
}

std::optional<ShardSpec> ShardFromEnvironment(const char* (*getenv_fn)(const char*)) {
  if (!getenv_fn) getenv_fn = SystemGetenv;
  const char* slurm_id = getenv_fn("SLURM_ARRAY_TASK_ID");
  if (slurm_id) {
    const char* slurm_count = getenv_fn("SLURM_ARRAY_TASK_COUNT");
    if (!slurm_count) {
      throw InputError(
          "environment", "SLURM_ARRAY_TASK_COUNT",
          "set together with SLURM_ARRAY_TASK_ID (use sbatch --array=0-(N-1))");
    }
    return ParseShard(std::string(slurm_id) + "/" + slurm_count,
                      "SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT");
  }
  const char* k8s_index = getenv_fn("JOB_COMPLETION_INDEX");
  if (k8s_index) {
    const char* count = getenv_fn("HANDLABEL_SHARD_COUNT");
    if (!count) {
      throw InputError("environment", "HANDLABEL_SHARD_COUNT",
                       "the Indexed Job's completions, set in the pod spec");
    }
    return ParseShard(std::string(k8s_index) + "/" + count,
                      "JOB_COMPLETION_INDEX/HANDLABEL_SHARD_COUNT");
  }
  return std::nullopt;
}

std::vector<std::string> FramesOfShard(const std::vector<std::string>& all_frames,
                                       const ShardSpec& shard) {
  HL_CHECK(shard.count >= 1 && shard.index >= 0 && shard.index < shard.count, "shard");
  const size_t n = all_frames.size();
  const size_t begin = n * shard.index / shard.count;
  const size_t end = n * (shard.index + 1) / shard.count;
  return {all_frames.begin() + begin, all_frames.begin() + end};
}

}  // namespace handlabel
