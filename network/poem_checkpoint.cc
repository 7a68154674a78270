#include "network/poem_checkpoint.h"

#include <filesystem>
#include <set>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr const char* kFormat = "handlabel-poem-checkpoint-1";

std::string ShapeString(const torch::Tensor& t) {
  std::string s = "(";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + ")";
}

std::string JoinLimited(const std::vector<std::string>& items, size_t limit = 20) {
  std::string s;
  for (size_t i = 0; i < items.size() && i < limit; ++i) s += (i ? ", " : "") + items[i];
  if (items.size() > limit) s += ", ... (" + std::to_string(items.size()) + " in all)";
  return s;
}

struct Archive {
  PoemConfig config;
  std::map<std::string, torch::Tensor> tensors;
};

Archive ReadArchive(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "", "an existing POEM checkpoint file", "no such file");
  }
  torch::serialize::InputArchive archive;
  try {
    archive.load_from(path);
  } catch (const std::exception& e) {
    throw InputError(path, "", "a handlabel POEM checkpoint (LibTorch archive)",
                     std::string("unreadable: ") + e.what());
  }
  c10::IValue format, config, state;
  if (!archive.try_read("format", format) || !format.isString() ||
      format.toStringRef() != kFormat) {
    throw InputError(path, "format", kFormat,
                     format.isString() ? format.toStringRef() : "missing");
  }
  if (!archive.try_read("config", config) || !config.isString()) {
    throw InputError(path, "config", "the embedded POEM config (JSON string)", "missing");
  }
  if (!archive.try_read("state_dict", state) || !state.isGenericDict()) {
    throw InputError(path, "state_dict", "a dictionary of tensors", "missing");
  }
  Archive a;
  a.config = PoemConfig::FromJson(config.toStringRef(), path + " (embedded config)");
  for (const auto& item : state.toGenericDict()) {
    a.tensors[item.key().toStringRef()] = item.value().toTensor();
  }
  return a;
}

}  // namespace

std::map<std::string, torch::Tensor> PoemStateDict(PoemModel& model) {
  std::map<std::string, torch::Tensor> out;
  for (const auto& p : model->named_parameters()) out[p.key()] = p.value();
  for (const auto& b : model->named_buffers()) out[b.key()] = b.value();
  return out;
}

StateDictReport LoadPoemStateDict(PoemModel& model,
                                  const std::map<std::string, torch::Tensor>& tensors,
                                  const std::string& source,
                                  const std::vector<std::string>& ignored_prefixes) {
  StateDictReport report;
  std::map<std::string, torch::Tensor> target = PoemStateDict(model);
  std::vector<std::string> shape_errors;
  for (const auto& [key, value] : tensors) {
    bool ignore = false;
    for (const auto& prefix : ignored_prefixes) ignore |= key.rfind(prefix, 0) == 0;
    if (ignore) {
      report.ignored.push_back(key);
      continue;
    }
    auto it = target.find(key);
    if (it == target.end()) {
      report.unexpected.push_back(key);
      continue;
    }
    if (!value.sizes().equals(it->second.sizes())) {
      shape_errors.push_back(key + " " + ShapeString(value) + " vs model " +
                             ShapeString(it->second));
    } else if (value.is_floating_point() && !torch::isfinite(value).all().item<bool>()) {
      throw InputError(source, key, "finite values", "NaN or infinity");
    }
  }
  for (const auto& [key, value] : target) {
    if (!tensors.count(key)) report.missing.push_back(key);
  }
  if (!shape_errors.empty() || !report.missing.empty() || !report.unexpected.empty()) {
    std::string got;
    if (!shape_errors.empty())
      got += "shape mismatches: " + JoinLimited(shape_errors) + "; ";
    if (!report.missing.empty())
      got += "missing keys: " + JoinLimited(report.missing) + "; ";
    if (!report.unexpected.empty()) {
      got += "unexpected keys: " + JoinLimited(report.unexpected) + "; ";
    }
    throw InputError(
        source, "state_dict",
        "the keys and shapes of a POEM model with config " + model->config().ToJson(),
        got);
  }
  torch::NoGradGuard no_grad;
  for (auto& [key, dst] : target) {
    dst.copy_(tensors.at(key).to(dst.scalar_type()));
  }
  return report;
}

void SavePoemCheckpoint(PoemModel& model, const std::string& path) {
  c10::Dict<std::string, at::Tensor> dict;
  for (const auto& [key, value] : PoemStateDict(model)) {
    dict.insert(key, value.detach().clone());
  }
  torch::serialize::OutputArchive archive;
  archive.write("format", c10::IValue(std::string(kFormat)));
  archive.write("config", c10::IValue(model->config().ToJson()));
  archive.write("state_dict", c10::IValue(dict));
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  // Write next to the target and rename, so a killed job never leaves half a file.
  const std::string tmp = path + ".tmp";
  archive.save_to(tmp);
  std::filesystem::rename(tmp, path);
}

PoemConfig ReadPoemCheckpointConfig(const std::string& path) {
  return ReadArchive(path).config;
}

PoemModel LoadPoemCheckpoint(const std::string& path) {
  Archive a = ReadArchive(path);
  PoemModel model(a.config);
  LoadPoemStateDict(model, a.tensors, path);
  return model;
}

void LoadPoemCheckpointInto(PoemModel& model, const std::string& path,
                            bool mask_head_may_differ) {
  Archive a = ReadArchive(path);
  if (mask_head_may_differ && model->config().mask_head && !a.config.mask_head) {
    a.config.mask_head = true;
    for (const auto& [key, value] : PoemStateDict(model)) {
      if (key.rfind("mask_head.", 0) == 0) a.tensors[key] = value.detach().clone();
    }
  } else if (mask_head_may_differ && !model->config().mask_head && a.config.mask_head) {
    a.config.mask_head = false;
    for (auto it = a.tensors.begin(); it != a.tensors.end();) {
      it = it->first.rfind("mask_head.", 0) == 0 ? a.tensors.erase(it) : std::next(it);
    }
  }
  const std::vector<std::string> diff = model->config().Differences(a.config);
  if (!diff.empty()) {
    std::string got;
    for (const auto& d : diff) got += (got.empty() ? "" : "; ") + d;
    throw InputError(path, "config", "the model's POEM config",
                     "a checkpoint for another config (model vs file: " + got + ")");
  }
  LoadPoemStateDict(model, a.tensors, path);
}

PoemModel AveragePoemCheckpoints(const std::vector<std::string>& paths) {
  if (paths.empty()) {
    throw InputError("checkpoint average", "", "at least one checkpoint", "none");
  }
  PoemModel mean = LoadPoemCheckpoint(paths.front());
  // Sums in float64 so that the order of the files does not change the result.
  std::map<std::string, torch::Tensor> sums;
  for (const auto& [key, value] : PoemStateDict(mean)) {
    if (value.is_floating_point()) sums[key] = value.to(torch::kDouble);
  }
  for (size_t i = 1; i < paths.size(); ++i) {
    PoemModel next(mean->config());
    LoadPoemCheckpointInto(next, paths[i]);  // throws on another config
    for (const auto& [key, value] : PoemStateDict(next)) {
      if (value.is_floating_point()) {
        sums.at(key) += value.to(torch::kDouble);
      } else if (i + 1 == paths.size()) {
        torch::NoGradGuard no_grad;
        PoemStateDict(mean).at(key).copy_(value);
      }
    }
  }
  torch::NoGradGuard no_grad;
  const double n = static_cast<double>(paths.size());
  for (auto& [key, dst] : PoemStateDict(mean)) {
    if (sums.count(key)) dst.copy_((sums.at(key) / n).to(dst.scalar_type()));
  }
  return mean;
}

}  // namespace handlabel
