#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "pipeline/job_config.h"
#include "pipeline/shard.h"
#include "pipeline/smooth_job.h"

namespace handlabel {

int RunSmooth(int argc, char** argv) {
  CLI::App app(
      "Smooth a labelled job over time (job section `sequence`, docs/labeling-jobs.md "
      "\"Sequences\"): one hand shape for the whole sequence, windows of consecutive "
      "frames refitted jointly to the same 2D evidence with a keypoint acceleration "
      "prior, blended on their overlaps. Writes output.dir/smoothed/ (labels, meshes, "
      "summary.json); the per-frame labels stay as they are. Resumable: frames already "
      "smoothed are skipped.\n"
      "Example: handlabel smooth --job jobs/sequence.yaml",
      "smooth");
  std::string job_file, shard_text;
  bool force = false, quiet = false;
  app.add_option("--job", job_file, "job YAML file, labelled before")->required();
  app.add_option("--shard", shard_text,
                 "write only the frames of shard i of N (0-based); its windows read "
                 "their neighbours' labels as context");
  app.add_flag("--force", force, "smooth every frame of the shard again");
  app.add_flag("--quiet", quiet, "print only errors");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("smooth", [&] {
    const JobConfig job = LoadJobConfig(job_file);
    SmoothRunOptions options;
    if (!shard_text.empty()) {
      options.shard = ParseShard(shard_text);
    } else if (const auto from_env = ShardFromEnvironment()) {
      options.shard = *from_env;
    }
    options.force = force;
    options.log = quiet ? nullptr : &std::cerr;
    const SmoothSummary summary = RunSmoothJob(job, options);
    if (!quiet) {
      std::cerr << "smooth: " << summary.frames << " frames of shard "
                << options.shard.ToString() << ": " << summary.smoothed
                << " smoothed now, " << summary.skipped << " before, "
                << summary.unlabelled << " without a per-frame label, " << summary.windows
                << " windows solved; " << SmoothedOutputDir(job.output_dir) << "\n";
    }
    return 0;
  });
}

}  // namespace handlabel
