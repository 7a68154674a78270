#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/sha256.h"
#include "pipeline/job_config.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {

int RunMerge(int argc, char** argv) {
  CLI::App app(
      "Join the shards of a labeling job: reads every shard log in output.dir/shards, "
      "writes output.dir/manifest.json (every frame: status, path, label file), "
      "summary.json and summary.md, and prints the summary. Exit status 1 when some "
      "frames have not been labelled by any shard yet.\n"
      "Example: handlabel merge --job jobs/demo.yaml",
      "merge");
  std::string job_file;
  app.add_option("--job", job_file, "job YAML file (the same as for 'handlabel label')")
      ->required();
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("merge", [&] {
    const JobConfig job = LoadJobConfig(job_file);
    const auto source = BuildFrameSource(job);
    const std::vector<std::string> frames = JobFrames(job, *source);
    const std::string weights_sha =
        job.network_weights.empty() ? "" : Sha256OfFile(job.network_weights);
    const LabelSummary summary =
        MergeLabelOutputs(job.output_dir, job.name, JobHash(job, weights_sha), frames);
    std::cout << summary.ToText() << "manifest: " << ManifestPath(job.output_dir)
              << "\nsummary: " << SummaryMarkdownPath(job.output_dir) << "\n";
    return summary.missing > 0 ? 1 : 0;
  });
}

}  // namespace handlabel
