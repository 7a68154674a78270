#include "pipeline/job_stamp.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "pipeline/label_outputs.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// Creates `path` with `content` unless it exists (no-replace, so that shards starting
// together cannot overwrite each other's stamp); false if it existed.
bool CreateFileIfAbsent(const std::string& path, const std::string& content) {
  const std::string staged = path + ".tmp." + std::to_string(::getpid()) + ".new";
  WriteFileAtomically(staged, content);
  const bool created = ::link(staged.c_str(), path.c_str()) == 0;
  const int error = errno;
  fs::remove(staged);
  if (!created && error != EEXIST) {
    throw InputError(path, "", "a job stamp the run can create", std::strerror(error));
  }
  return created;
}

}  // namespace

std::string RecordedJobHash(const std::string& output_dir) {
  const std::string stamp = JobStampPath(output_dir);
  std::ifstream in(stamp);
  if (!in) {
    throw InputError(stamp, "", "the job stamp of a labelled job (run `handlabel label`)",
                     "missing");
  }
  try {
    return nlohmann::json::parse(in).at("job_hash").get<std::string>();
  } catch (const std::exception& e) {
    throw InputError(stamp, "job_hash", "a job stamp written by handlabel", e.what());
  }
}

void ClaimOutputFolder(const JobConfig& job, const std::string& job_hash, bool force,
                       OutputFolderLock* lock) {
  const std::string stamp = JobStampPath(job.output_dir);
  const nlohmann::json j = {
      {"job", job.name}, {"job_hash", job_hash}, {"job_file", job.source_file}};
  if (!fs::exists(stamp) && CreateFileIfAbsent(stamp, j.dump(1) + "\n")) return;
  const std::string recorded = RecordedJobHash(job.output_dir);
  if (recorded == job_hash) return;
  if (!force) {
    throw InputError(stamp, "job_hash",
                     "this job's hash " + job_hash +
                         " (the folder holds labels of a different job or job version; "
                         "use another output.dir, or --force to relabel every frame)",
                     recorded);
  }
  lock->MakeWhole("replace " + stamp + " of another job");
  // The other job's records describe labels this job replaces: none may count as done.
  std::error_code ignored;
  for (const auto& e :
       fs::directory_iterator(fs::path(job.output_dir) / "shards", ignored)) {
    if (e.path().extension() == ".jsonl") fs::remove(e.path(), ignored);
  }
  WriteFileAtomically(stamp, j.dump(1) + "\n");
}

}  // namespace handlabel
