#include <unistd.h>

#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/progress.h"
#include "pipeline/job_config.h"
#include "pipeline/label_job.h"
#include "pipeline/label_stage_factory.h"
#include "pipeline/shard.h"
#include "pipeline/smooth_job.h"

namespace handlabel {

int RunLabel(int argc, char** argv) {
  CLI::App app(
      "Label the frames of a capture as a job described by a YAML file (fields in "
      "docs/labeling-jobs.md): read -> network -> quality checks -> refine or fallback "
      "fit -> one label JSON per frame in output.dir/labels.\n"
      "Example: handlabel label --job jobs/demo.yaml\n"
      "Cluster: each task runs one shard (--shard i/N, or SLURM_ARRAY_TASK_ID and "
      "SLURM_ARRAY_TASK_COUNT, or JOB_COMPLETION_INDEX and HANDLABEL_SHARD_COUNT); "
      "afterwards 'handlabel merge --job ...' joins the shards.",
      "label");
  std::string job_file, shard_text;
  bool resume = false, force = false, quiet = false;
  app.add_option("--job", job_file, "job YAML file")->required();
  app.add_option(
      "--shard", shard_text,
      "label only shard i of N (0-based, e.g. 3/16); default: from the cluster "
      "environment, else the whole job");
  app.add_flag("--resume", resume,
               "skip frames finished by earlier runs (a killed or failed run continues)");
  app.add_flag("--force", force, "label every frame of the shard again");
  app.add_flag("--quiet", quiet, "print only errors");
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  if (resume && force) {
    std::cerr << "handlabel label: --resume and --force exclude each other\n";
    return 2;
  }
  return RunReportingErrors("label", [&] {
    const JobConfig job = LoadJobConfig(job_file);
    if (job.network_weights.empty()) UseOneMallocArena();
    LabelRunOptions options;
    if (!shard_text.empty()) {
      options.shard = ParseShard(shard_text);
    } else if (const auto from_env = ShardFromEnvironment()) {
      options.shard = *from_env;
    }
    options.resume = resume;
    options.force = force;
    options.interactive = Progress::IsTerminal(STDERR_FILENO);
    options.log = quiet ? nullptr : &std::cerr;
    const BuiltLabelStages stages = BuildLabelStages(job);
    if (!stages.hand_model_note.empty() && !quiet)
      std::cerr << "handlabel label: note: " << stages.hand_model_note << "\n";
    const LabelSummary summary = RunLabelJob(job, stages.Set(), options);
    if (summary.failed > 0 && summary.ok == 0) return 1;
    // A whole-job run smooths right away; shards smooth with `handlabel smooth` once
    // every shard has labelled (windows read their neighbours' labels).
    if (job.sequence.smooth && options.shard.count == 1) {
      SmoothRunOptions smooth;
      smooth.force = force;
      smooth.log = options.log;
      RunSmoothJob(job, smooth);
    }
    return 0;
  });
}

}  // namespace handlabel
