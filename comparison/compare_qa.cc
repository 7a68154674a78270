#include "comparison/compare_qa.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace handlabel {
namespace {

// One answer: its checks as recorded in its label, and its error.
struct Answer {
  double error_mm = 0;
  bool fixed_checks_pass = true;  // finite, range, enough_views
  double reprojection_px = INFINITY, view_agreement_mm = INFINITY;
};

bool Kept(const Answer& a, double max_reprojection_px, double max_disagreement_mm) {
  return a.fixed_checks_pass && a.reprojection_px <= max_reprojection_px &&
         a.view_agreement_mm <= max_disagreement_mm;
}

double Value(const Answer& a, const std::string& check) {
  return check == "reprojection" ? a.reprojection_px : a.view_agreement_mm;
}

// Flagged = value > threshold (a non-finite value is always flagged).
bool Flagged(double value, double threshold) {
  return !std::isfinite(value) || value > threshold;
}

RocPoint RocAt(const std::vector<Answer>& answers, const std::string& check,
               double threshold, double error_mm) {
  int bad = 0, good = 0, flagged_bad = 0, flagged_good = 0;
  for (const Answer& a : answers) {
    const bool is_bad = a.error_mm > error_mm;
    const bool flagged = Flagged(Value(a, check), threshold);
    (is_bad ? bad : good) += 1;
    if (flagged) (is_bad ? flagged_bad : flagged_good) += 1;
  }
  return {threshold, good > 0 ? double(flagged_good) / good : 0.0,
          bad > 0 ? double(flagged_bad) / bad : 0.0};
}

// Every distinct finite value as a threshold, plus one below all (flag everything).
std::vector<double> CandidateThresholds(const std::vector<Answer>& answers,
                                        const std::string& check) {
  std::set<double> values;
  for (const Answer& a : answers) {
    const double v = Value(a, check);
    if (std::isfinite(v)) values.insert(v);
  }
  std::vector<double> t(values.begin(), values.end());
  t.insert(t.begin(), t.empty() ? 0.0 : t.front() - 1.0);
  return t;
}

// The threshold with the largest Youden J on `answers`; `fallback` (the current one)
// when no threshold beats it, or when the set has no bad or no good answer (J is then
// meaningless).
double ChooseThreshold(const std::vector<Answer>& answers, const std::string& check,
                       double error_mm, double fallback) {
  int bad = 0;
  for (const Answer& a : answers) bad += a.error_mm > error_mm;
  if (bad == 0 || bad == static_cast<int>(answers.size())) return fallback;
  // Start from the current threshold: a new one must do strictly better.
  const RocPoint at_current = RocAt(answers, check, fallback, error_mm);
  double best = fallback;
  double best_j = at_current.true_positive_rate - at_current.false_positive_rate;
  for (double t : CandidateThresholds(answers, check)) {
    const RocPoint p = RocAt(answers, check, t, error_mm);
    const double j = p.true_positive_rate - p.false_positive_rate;
    if (j > best_j + 1e-12) {
      best_j = j;
      best = t;
    }
  }
  return best;
}

void PrecisionRecall(const std::vector<Answer>& answers, const std::string& check,
                     double threshold, double error_mm, double* precision,
                     double* recall) {
  int flagged = 0, flagged_bad = 0, bad = 0;
  for (const Answer& a : answers) {
    const bool is_bad = a.error_mm > error_mm;
    const bool f = Flagged(Value(a, check), threshold);
    bad += is_bad;
    flagged += f;
    flagged_bad += f && is_bad;
  }
  *precision = flagged > 0 ? double(flagged_bad) / flagged : 0.0;
  *recall = bad > 0 ? double(flagged_bad) / bad : 0.0;
}

KeptShare Share(const std::vector<Answer>& answers, const QualityThresholds& t,
                double error_mm) {
  KeptShare s;
  s.answers = static_cast<int>(answers.size());
  for (const Answer& a : answers) {
    if (!Kept(a, t.max_reprojection_px, t.max_view_disagreement_mm)) continue;
    ++s.kept;
    s.kept_bad += a.error_mm > error_mm;
  }
  return s;
}

// A network label's recorded checks (nullopt without checks) with its error.
std::optional<Answer> AnswerOf(const std::optional<LabelRecord>& label, double error_mm) {
  if (!label || label->quality.flags.empty()) return std::nullopt;
  Answer a;
  a.error_mm = error_mm;
  for (const QualityFlag& flag : label->quality.flags) {
    if (flag.name == "reprojection") {
      a.reprojection_px = flag.value;
    } else if (flag.name == "view_agreement") {
      a.view_agreement_mm = flag.value;
    } else if (!flag.passed) {
      a.fixed_checks_pass = false;
    }
  }
  return a;
}

std::vector<Answer> ReadAnswers(const MethodRun& network) {
  std::vector<Answer> answers;
  const MethodScores& s = network.scores;
  for (size_t f = 0; f < s.frames.size(); ++f) {
    const std::optional<Answer> a =
        AnswerOf(MethodLabel(network, s.frames[f]), 1000 * s.per_frame[f].mpjpe);
    if (a) answers.push_back(*a);
  }
  return answers;
}

// An earlier comparison's network answers: per-frame MPJPE from its compare.json,
// checks from its labels in methods/network/.
std::vector<Answer> ReadAnswers(const std::string& compare_dir) {
  namespace fs = std::filesystem;
  const std::string path = (fs::path(compare_dir) / "compare.json").string();
  std::ifstream in(path);
  if (!in) throw InputError("--qa-selection", path, "a compare.json (compare --out)");
  nlohmann::json compare;
  try {
    compare = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw InputError(path, "(file)", "JSON", e.what());
  }
  MethodRun network;
  network.method = CompareMethod::kNetwork;
  network.output_dir = (fs::path(compare_dir) / "methods" / "network").string();
  for (const nlohmann::json& m : compare.value("methods", nlohmann::json::array())) {
    if (m.value("method", "") != "network" || !m.value("ran", false) ||
        !m.contains("per_frame_mpjpe_mm")) {
      continue;
    }
    std::vector<Answer> answers;
    for (const auto& [frame, mm] : m.at("per_frame_mpjpe_mm").items()) {
      const std::optional<Answer> a =
          AnswerOf(MethodLabel(network, frame), mm.get<double>());
      if (a) answers.push_back(*a);
    }
    return answers;
  }
  throw InputError(path, "methods",
                   "a network row that ran with ground truth (compare with the network "
                   "method and weights)");
}

}  // namespace

QualityStudy StudyQualityChecks(const MethodRun& network,
                                const QualityThresholds& current, double error_mm,
                                const std::vector<std::string>& selection_dirs) {
  QualityStudy study;
  study.error_mm = error_mm;
  study.current = current;
  study.chosen = current;
  study.selection_dirs = selection_dirs;
  if (network.method != CompareMethod::kNetwork || !network.why_not.empty()) {
    study.why_not = "the network alone did not run" +
                    (network.why_not.empty() ? "" : ": " + network.why_not);
    return study;
  }
  const std::vector<Answer> answers = ReadAnswers(network);
  std::vector<Answer> selection, held_out;
  if (selection_dirs.empty()) {
    for (size_t i = 0; i < answers.size(); ++i)
      (i % 2 == 0 ? selection : held_out).push_back(answers[i]);
  } else {
    held_out = answers;
    for (const std::string& dir : selection_dirs) {
      const std::vector<Answer> more = ReadAnswers(dir);
      selection.insert(selection.end(), more.begin(), more.end());
    }
  }
  if (selection.size() < 2 || held_out.size() < 2) {
    study.why_not = "fewer than 4 network answers with ground truth (" +
                    std::to_string(selection.size()) + " to choose on, " +
                    std::to_string(held_out.size()) + " held out)";
    return study;
  }
  for (const Answer& a : answers) study.bad_frames += a.error_mm > error_mm;
  study.frames = static_cast<int>(answers.size());
  study.selection_frames = static_cast<int>(selection.size());
  study.held_out_frames = static_cast<int>(held_out.size());
  const std::vector<std::pair<std::string, std::string>> checks = {
      {"reprojection", "px"}, {"view_agreement", "mm"}};
  for (const auto& [name, unit] : checks) {
    CheckStudy c;
    c.name = name;
    c.unit = unit;
    for (const Answer& a : answers) {
      c.values.push_back(Value(a, name));
      c.errors_mm.push_back(a.error_mm);
    }
    for (double t : CandidateThresholds(answers, name))
      c.roc.push_back(RocAt(answers, name, t, error_mm));
    c.roc.push_back({INFINITY, 0.0, 0.0});  // flag nothing (non-finite still flagged)
    std::sort(c.roc.begin(), c.roc.end(), [](const RocPoint& a, const RocPoint& b) {
      return a.false_positive_rate < b.false_positive_rate ||
             (a.false_positive_rate == b.false_positive_rate &&
              a.true_positive_rate < b.true_positive_rate);
    });
    for (size_t i = 1; i < c.roc.size(); ++i) {
      c.roc_auc += (c.roc[i].false_positive_rate - c.roc[i - 1].false_positive_rate) *
                   (c.roc[i].true_positive_rate + c.roc[i - 1].true_positive_rate) / 2;
    }
    // With one class empty the ROC is undefined.
    if (study.bad_frames == 0 || study.bad_frames == study.frames) c.roc_auc = NAN;
    c.current = name == "reprojection" ? current.max_reprojection_px
                                       : current.max_view_disagreement_mm;
    c.chosen = ChooseThreshold(selection, name, error_mm, c.current);
    c.at_current = RocAt(answers, name, c.current, error_mm);
    c.at_chosen = RocAt(answers, name, c.chosen, error_mm);
    PrecisionRecall(held_out, name, c.current, error_mm, &c.precision_current,
                    &c.recall_current);
    PrecisionRecall(held_out, name, c.chosen, error_mm, &c.precision_chosen,
                    &c.recall_chosen);
    (name == "reprojection" ? study.chosen.max_reprojection_px
                            : study.chosen.max_view_disagreement_mm) = c.chosen;
    study.checks.push_back(std::move(c));
  }
  study.before = Share(held_out, current, error_mm);
  study.after = Share(held_out, study.chosen, error_mm);
  return study;
}

}  // namespace handlabel
