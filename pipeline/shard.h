#pragma once
// Splitting a job's frames over cluster tasks. A shard is "index/count" (0-based). The
// partition is deterministic and contiguous: shard i gets frames
// [floor(i*F/N), floor((i+1)*F/N)) of the job's sorted frame list, so consecutive
// frames (useful for temporal smoothing and for locality of reads) stay together and
// every frame lands in exactly one shard.

#include <optional>
#include <string>
#include <vector>

namespace handlabel {

struct ShardSpec {
  int index = 0;
  int count = 1;
  std::string ToString() const {
    return std::to_string(index) + "/" + std::to_string(count);
  }
};

// Parses "i/N" with 0 <= i < N; throws InputError naming `source` otherwise.
ShardSpec ParseShard(const std::string& text, const std::string& source = "--shard");

// From the environment of a cluster task: SLURM_ARRAY_TASK_ID with
// SLURM_ARRAY_TASK_COUNT (SLURM job arrays), or JOB_COMPLETION_INDEX with
// HANDLABEL_SHARD_COUNT (Kubernetes Indexed Jobs do not export the completion count,
// so the manifest sets it). Nothing when neither is set; InputError when malformed.
// `getenv` is injectable for tests.
std::optional<ShardSpec> ShardFromEnvironment(
    const char* (*getenv_fn)(const char*) = nullptr);

// The frames of `shard` from the full sorted list, as described above.
std::vector<std::string> FramesOfShard(const std::vector<std::string>& all_frames,
                                       const ShardSpec& shard);

}  // namespace handlabel
