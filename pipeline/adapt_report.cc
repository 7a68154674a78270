#include "pipeline/adapt_run.h"

// `handlabel adapt`'s measurements (pipeline/adapt.h): the starting and the adapted
// network alone on the held-out frames against their fit labels, the quality checks'
// thresholds chosen on the adapted answers (adapt_thresholds.h), and the model card
// that reports the run.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/json_util.h"
#include "core/text.h"
#include "hand/metrics.h"
#include "network/poem/poem_trainer.h"
#include "pipeline/adapt_thresholds.h"
#include "pipeline/build_info.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace adapt {
namespace {

// A job's held-out answers judged against their fit labels.
std::vector<JudgedAnswer> JudgeAnswers(const AdaptRun& run, const std::string& job_dir,
                                       double* mpvpe_mm) {
  std::vector<JudgedAnswer> answers;
  double vertices = 0;
  for (const std::string& id : WithFitLabel(run, run.heldout)) {
    const LabelRecord answer = ReadLabelFile(LabelFilePath(job_dir, id));
    const LabelRecord fit = ReadLabelFile(LabelFilePath(run.Path("fit"), id));
    answers.push_back({1000 * MeanPointError(answer.mesh.keypoints, fit.mesh.keypoints),
                       answer.quality});
    vertices += 1000 * MeanPointError(answer.mesh.vertices, fit.mesh.vertices);
  }
  *mpvpe_mm = vertices / std::max<size_t>(answers.size(), 1);
  return answers;
}

nlohmann::json AnswersJson(const std::vector<JudgedAnswer>& answers, double mpvpe_mm) {
  double joints = 0;
  int passed = 0;
  for (const JudgedAnswer& a : answers) {
    joints += a.error_mm;
    bool all = true;
    for (const QualityFlag& f : a.quality.flags) all = all && f.passed;
    passed += all;
  }
  return {{"frames", answers.size()},
          {"mpjpe_mm_vs_fit_labels", joints / std::max<size_t>(answers.size(), 1)},
          {"mpvpe_mm_vs_fit_labels", mpvpe_mm},
          {"passed_every_check", passed}};
}

// The adapted network's thresholds, chosen on its held-out answers
// (adapt_thresholds.h), for the label stage (heldout.json's thresholds).
void ChooseAdaptedThresholds(const AdaptRun& run,
                             const std::vector<JudgedAnswer>& answers,
                             const QualityThresholds& current, nlohmann::json* result) {
  ThresholdStudy study;
  const QualityThresholds chosen =
      ChooseThresholds(answers, current, run.o.accept_mm, &study);
  nlohmann::json json = study.ToJson();
  json["refine"] = {{"max_reprojection_px", chosen.max_reprojection_px},
                    {"max_view_disagreement_mm", chosen.max_view_disagreement_mm},
                    {"max_detector_rms_px", chosen.max_detector_rms_px}};
  (*result)["thresholds"] = json;
}

// Frames per second of the stages together (0 when they took no time).
double FramesPerSecond(const AdaptRun& run, std::initializer_list<const char*> stages) {
  double seconds = 0;
  for (const char* stage : stages) seconds += run.progress.value(stage, 0.0);
  return seconds > 0 ? run.frames.size() / seconds : 0.0;
}

// A number of the card for reading: 3 significant digits.
std::string Sig(const nlohmann::json& value) {
  if (!value.is_number()) return value.dump();
  std::ostringstream out;
  out.precision(3);
  out << value.get<double>();
  return out.str();
}

std::string HeldoutLine(const nlohmann::json& h, const std::string& name) {
  if (!h.contains(name)) return "";
  const nlohmann::json& r = h[name];
  return "| " + name + " | " + Sig(r["mpjpe_mm_vs_fit_labels"]) + " | " +
         Sig(r["mpvpe_mm_vs_fit_labels"]) + " | " + r["passed_every_check"].dump() +
         " of " + r["frames"].dump() + " |\n";
}

}  // namespace

// The network alone (no refine) before and after, on the held-out frames.
void HeldoutStage(const AdaptRun& run) {
  nlohmann::json result = nlohmann::json::object();
  const std::pair<std::string, std::string> runs[] = {{"before", run.o.weights},
                                                      {"after", run.Path("network.pt")}};
  for (auto [name, weights] : runs) {
    const int views = PoemCheckpointConfig(weights).num_views;
    if (views != run.num_cameras) {
      // The starting weights as they start the training: at the capture's view count.
      const std::string converted = run.Path(
          "heldout/start_weights_" + std::to_string(run.num_cameras) + "_views.pt");
      WritePoemCheckpointForViews(weights, run.num_cameras, converted);
      run.Say("heldout: the starting weights are for " + std::to_string(views) +
              " views, measured at the capture's " + std::to_string(run.num_cameras) +
              " (" + converted + ")");
      weights = converted;
    }
    const std::string dir = run.Path("heldout/" + name);
    JobConfig job = CaptureJob(run, "adapt-heldout-" + name, dir);
    job.frames = Join(run.heldout, ",");
    job.network_weights = weights;
    job.refine_mode = RefineMode::kOff;
    const LabelSummary summary = RunJob(run, job);
    double mpvpe_mm = 0;
    const std::vector<JudgedAnswer> answers = JudgeAnswers(run, dir, &mpvpe_mm);
    result[name] = AnswersJson(answers, mpvpe_mm);
    result[name]["weights"] = weights;
    if (name == "after") ChooseAdaptedThresholds(run, answers, job.quality, &result);
    result[name]["job_metrics"] = summary.ToJson().value("metrics", nlohmann::json());
    run.Say(
        "heldout: network " + name + ": " +
        FormatNumber(
            std::round(10 * result[name]["mpjpe_mm_vs_fit_labels"].get<double>()) / 10) +
        " mm from the fit labels (" + dir + ")");
  }
  WriteFileAtomically(run.Path("heldout/heldout.json"), result.dump(1) + "\n");
}

// What the network learned from, how long, and what it measures on held-out frames.
nlohmann::json ModelCard(const AdaptRun& run) {
  const nlohmann::json selection =
      ReadJsonFileStrict(run.Path("train/capture_labels.json"));
  const nlohmann::json summary = ReadIfExists(run.Path("summary.json"));
  const nlohmann::json detection = ReadIfExists(run.Path("detect.json"));
  const bool detected = detection.is_object() && detection.value("ran", false);
  nlohmann::json card = {
      {"format", "handlabel-adapt-card"},
      {"capture", run.o.capture_dir},
      {"cameras", run.num_cameras},
      {"frames", run.frames.size()},
      {"options", AdaptOptionsJson(run.o)},
      {"start_weights", run.o.weights},
      {"network", run.Path("network.pt")},
      {"training_frames", run.train.size()},
      {"training_frames_with_fit_label", selection["training_frames"]},
      {"training_labels_kept", selection["kept"]},
      {"selection_rule", selection["rule"]},
      {"heldout_frames", run.heldout.empty()
                             ? nlohmann::json()
                             : nlohmann::json{run.heldout.front(), run.heldout.back()}},
      {"plan", ReadJsonFileStrict(run.Path("train/plan.json"))},
      {"export", ReadIfExists(run.Path("export.json"))},
      {"heldout", ReadIfExists(run.Path("heldout/heldout.json"))},
      {"labels_by_path", summary.is_object() ? summary.value("by_path", nlohmann::json())
                                             : nlohmann::json()},
      // The label stage reuses the detections: the detector's time is not in it.
      {"detection", detection},
      {"frames_per_second",
       {{"detect", detected ? FramesPerSecond(run, {"detect"}) : 0.0},
        {"fit_only", FramesPerSecond(run, {"fit"})},
        {"detect_and_fit", detected ? FramesPerSecond(run, {"detect", "fit"}) : 0.0},
        {"network_checks_fallback", FramesPerSecond(run, {"label"})}}},
      {"seconds", run.progress},
      {"total_seconds", run.ElapsedSeconds()},
      {"version", GetBuildInfo().version}};
  return card;
}

std::string JobForNewRecordings(const AdaptRun& run) {
  const nlohmann::json heldout = ReadIfExists(run.Path("heldout/heldout.json"));
  const bool chosen = heldout.is_object() && heldout.contains("thresholds");
  // JSON strings are YAML's double-quoted scalars: any path survives.
  auto quoted = [](const std::string& text) { return nlohmann::json(text).dump(); };
  std::ostringstream yaml;
  yaml << "# A label job for new recordings of this rig with the adapted network, "
          "written\n"
          "# by handlabel adapt (docs/adapt.md \"Labelling new recordings\"). Set "
          "input.path\n"
          "# to the new capture and output.dir, then: handlabel label --job <this file>\n"
       << "name: adapted\nseed: " << run.o.seed << "\n"
       << "input: {format: native, path: " << quoted(run.o.capture_dir) << "}\n"
       << "network: {weights: " << quoted(run.Path("network.pt"))
       << ", threads: " << run.o.threads
       // bf16 where the CPU has a bf16 unit: the same labels within rounding, faster
       // (docs/speed.md "Reduced precision").
       << ", precision: auto}\n"
       << "refine: {mode: fallback";
  if (chosen) {
    const nlohmann::json& refine = heldout["thresholds"]["refine"];
    for (const char* field :
         {"max_reprojection_px", "max_view_disagreement_mm", "max_detector_rms_px"}) {
      yaml << ", " << field << ": " << refine[field].dump();  // as chosen, unrounded
    }
  }
  yaml << "}\n"
       << "evidence: {keypoints_2d: detector, detector_every: "
       << kNewRecordingsDetectorEvery << ", masks: none}\n"
       << "output: {dir: " << quoted(run.Path("new_labels"))
       << ", overlays: " << (run.o.overlays ? "true" : "false") << "}\n";
  return yaml.str();
}

std::string ModelCardMarkdown(const nlohmann::json& card) {
  std::ostringstream md;
  const nlohmann::json& plan = card["plan"];
  md << "# Adapted network: " << card["network"].get<std::string>() << "\n\n"
     << "Started from " << card["start_weights"].get<std::string>() << ", trained "
     << plan["steps"] << " steps (" << Sig(plan["seconds_per_step"]) << " s/step on "
     << plan["threads"] << " threads of " << plan["cpu"].get<std::string>() << ") on "
     << card["training_labels_kept"] << " of " << card["training_frames"] << " ("
     << card["training_frames_with_fit_label"] << " with a fit label)"
     << " training frames of " << card["capture"].get<std::string>() << " ("
     << card["cameras"] << " cameras), their fit labels kept by the rule: "
     << card["selection_rule"].get<std::string>() << ".\n\n";
  if (card["heldout"].is_object()) {
    md << "Held-out frames " << card["heldout_frames"][0].get<std::string>() << " to "
       << card["heldout_frames"][1].get<std::string>()
       << " (never trained on), the network alone against their fit labels:\n\n"
       << "| weights | MPJPE mm | MPVPE mm | passed every check |\n|---|---|---|---|\n"
       << HeldoutLine(card["heldout"], "before") << HeldoutLine(card["heldout"], "after")
       << "\n";
  }
  if (card["heldout"].is_object() && card["heldout"].contains("thresholds")) {
    const nlohmann::json& t = card["heldout"]["thresholds"];
    md << "Quality-check thresholds chosen on the adapted answers (bad: farther than "
       << Sig(t["accept_mm"]) << " mm from the fit label; " << t["bad_answers"] << " of "
       << t["bad_answers"].get<int>() + t["good_answers"].get<int>()
       << " are): the joint decision's Youden's J " << Sig(t["youden_current"]) << " -> "
       << Sig(t["youden_chosen"]) << ", answers kept " << t["kept_current"] << " ("
       << t["kept_bad_current"] << " bad) -> " << t["kept_chosen"] << " ("
       << t["kept_bad_chosen"]
       << " bad).\n\n| check | current | chosen |\n|---|---|---|\n";
    for (const nlohmann::json& c : t["checks"]) {
      md << "| " << c["check"].get<std::string>() << " | " << Sig(c["current"]) << " | "
         << Sig(c["chosen"]) << " |\n";
    }
    md << "\nIn a label job with this network:\n\n```\nrefine: "
       << "{max_reprojection_px: " << Sig(t["refine"]["max_reprojection_px"])
       << ", max_view_disagreement_mm: " << Sig(t["refine"]["max_view_disagreement_mm"])
       << ", max_detector_rms_px: " << Sig(t["refine"]["max_detector_rms_px"])
       << "}\n```\n\n";
  }
  md << "Labels (network + checks + fallback fit): " << card["labels_by_path"].dump()
     << ".\n\nFrames per second: detector " << Sig(card["frames_per_second"]["detect"])
     << " (0: the capture had detections), fit only "
     << Sig(card["frames_per_second"]["fit_only"])
     << ", network + checks + fallback on the same detections "
     << Sig(card["frames_per_second"]["network_checks_fallback"])
     << ".\n\nSeconds per stage:";
  for (const auto& [stage, seconds] : card["seconds"].items()) {
    md << " " << stage << " " << Sig(seconds);
  }
  md << "; total " << Sig(card["total_seconds"]) << " ("
     << Sig(card["total_seconds"].get<double>() / 60) << " min).\n";
  return md.str();
}

}  // namespace adapt
}  // namespace handlabel
