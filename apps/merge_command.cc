#include <iostream>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "formats/sha256.h"
#include "pipeline/job_config.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_stage_factory.h"
#include "pipeline/output_lock.h"

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
    // One writer: no label run or other merge may use the folder meanwhile.
    const OutputFolderLock lock =
        OutputFolderLock::Whole(job.output_dir, "merge", job_file);
    std::vector<std::string> not_labelled;
    const LabelSummary summary = MergeLabelOutputs(
        job.output_dir, job.name, JobHash(job, weights_sha), frames, "", &not_labelled);
    std::cout << summary.ToText() << "manifest: " << ManifestPath(job.output_dir)
              << "\nsummary: " << SummaryMarkdownPath(job.output_dir) << "\n";
    if (!not_labelled.empty()) {
      std::cout << "not labelled (" << not_labelled.size() << "):\n";
      for (size_t i = 0; i < not_labelled.size() && i < 50; ++i) {
        std::cout << "  " << not_labelled[i] << "\n";
      }
      if (not_labelled.size() > 50) std::cout << "  ... (see the manifest)\n";
    }
    return summary.missing > 0 ? 1 : 0;
  });
}

}  // namespace handlabel
