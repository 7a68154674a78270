// The job stamp (`<output.dir>/job.json`): which job, and which version of it, a
// folder's labels belong to. A label run claims the folder with it; the smoothing pass
// and merges read it back (docs/labeling-jobs.md, "Output folder").
#pragma once

#include <string>

#include "pipeline/job_config.h"
#include "pipeline/output_lock.h"

namespace handlabel {

// The job hash the stamp in `output_dir` records. Throws InputError naming the stamp
// when it is missing or unreadable.
std::string RecordedJobHash(const std::string& output_dir);

// A folder holds the outputs of one job: writes this job's stamp if the folder has
// none, accepts a stamp with the same hash, and refuses another job's unless `force`
// (which needs the folder to itself, `lock`, and forgets the other job's shard logs).
void ClaimOutputFolder(const JobConfig& job, const std::string& job_hash, bool force,
                       OutputFolderLock* lock);

}  // namespace handlabel
