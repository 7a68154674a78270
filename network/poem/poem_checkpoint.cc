#include "network/poem/poem_checkpoint.h"

#include <caffe2/serialize/inline_container.h>
#include <torch/csrc/jit/api/compilation_unit.h>
#include <torch/csrc/jit/serialization/unpickler.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "network/poem/tensor_shape.h"

namespace handlabel {
namespace {

constexpr const char* kFormat = "handlabel-poem-checkpoint-1";

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

// Raw bytes of every storage record the unpickler asked for, by address, so that each
// tensor can be checked against the bytes really behind it.
using RecordSizes = std::map<const void*, size_t>;

// LibTorch 1.13 builds a storage of the size the pickle declares over whatever bytes
// the record holds, so a short record is read past its end by the first operation on
// the tensor. Every view must lie inside its record; checked before any element is
// read.
void CheckTensorInsideRecord(const torch::Tensor& t, const RecordSizes& records,
                             const std::string& path, const std::string& key) {
  if (t.numel() == 0) return;
  const auto record = records.find(t.storage().data());
  if (record == records.end()) {
    throw InputError(path, key, "a tensor stored in the archive", "no storage record");
  }
  int64_t last = t.storage_offset();
  for (int64_t d = 0; d < t.dim(); ++d) {
    if (t.stride(d) < 0 || last < 0) {
      throw InputError(path, key, "non-negative strides and offset", "negative");
    }
    const int64_t reach = (t.size(d) - 1);
    if (t.stride(d) > 0 &&
        reach > (std::numeric_limits<int64_t>::max() - last) / t.stride(d)) {
      throw InputError(path, key, "a view inside its storage", "an overflowing extent");
    }
    last += reach * t.stride(d);
  }
  const uint64_t needed = static_cast<uint64_t>(last + 1) * t.element_size();
  if (needed > record->second || t.storage().nbytes() > record->second) {
    throw InputError(
        path, key + " storage",
        "at least " + std::to_string(std::max<uint64_t>(needed, t.storage().nbytes())) +
            " bytes for shape " + ShapeString(t),
        std::to_string(record->second) + " bytes in the archive");
  }
}

// Decodes the archive's data.pkl with LibTorch's unpickler but none of its module
// import: the one object in it (the checkpoint, a `__torch__` module) is returned as
// its attribute dictionary, and every storage record's size is kept.
c10::IValue ReadCheckpointAttributes(const std::string& path, RecordSizes* records) {
  caffe2::serialize::PyTorchStreamReader reader(path);
  const auto [pickle, pickle_size] = reader.getRecord("data.pkl");
  const char* bytes = static_cast<const char*>(pickle.get());
  size_t offset = 0;
  const auto read = [&](char* buffer, size_t n) {
    n = std::min(n, pickle_size - offset);
    std::memcpy(buffer, bytes + offset, n);
    offset += n;
    return n;
  };
  auto unit = std::make_shared<torch::jit::CompilationUnit>();
  // Classes (the `__torch__` module) get a fresh class type; container tags such as
  // "Dict[str, Tensor]" (the unpickler asks the resolver for them too) are parsed.
  const auto resolve_type = [&](const c10::QualifiedName& name) {
    if (name.prefix().rfind("__torch__", 0) == 0) {
      return c10::StrongTypePtr(unit, c10::ClassType::create(name, unit));
    }
    return c10::StrongTypePtr(
        unit, torch::jit::Unpickler::defaultTypeParser(name.qualifiedName()));
  };
  c10::IValue attributes;
  int objects = 0;
  const auto load_object = [&](const c10::StrongTypePtr& type, c10::IValue state) {
    ++objects;
    attributes = std::move(state);
    return c10::ivalue::Object::create(type, 0);
  };
  const auto read_record = [&](const std::string& name) {
    auto [data, size] = reader.getRecord("data/" + name);
    (*records)[data.get()] = size;
    return std::move(data);
  };
  torch::jit::Unpickler unpickler(read, resolve_type, load_object, read_record,
                                  c10::Device(c10::kCPU));
  unpickler.parse_ivalue();
  if (objects != 1 || !attributes.isGenericDict()) {
    throw InputError(path, "data.pkl", "one checkpoint object with named attributes",
                     std::to_string(objects) + " objects");
  }
  return attributes;
}

c10::IValue Attribute(const c10::IValue& attributes, const std::string& name) {
  const auto dict = attributes.toGenericDict();
  const auto it = dict.find(name);
  return it == dict.end() ? c10::IValue() : it->value();
}

Archive ReadArchive(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "", "an existing POEM checkpoint file", "no such file");
  }
  RecordSizes records;
  c10::IValue attributes;
  try {
    attributes = ReadCheckpointAttributes(path, &records);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path, "", "a handlabel POEM checkpoint (LibTorch archive)",
                     "unreadable: " + TorchErrorText(e));
  }
  const c10::IValue format = Attribute(attributes, "format");
  if (!format.isString() || format.toStringRef() != kFormat) {
    throw InputError(path, "format", kFormat,
                     format.isString() ? format.toStringRef() : "missing");
  }
  const c10::IValue config = Attribute(attributes, "config");
  if (!config.isString()) {
    throw InputError(path, "config", "the embedded POEM config (JSON string)", "missing");
  }
  const c10::IValue state = Attribute(attributes, "state_dict");
  if (!state.isGenericDict()) {
    throw InputError(path, "state_dict", "a dictionary of tensors", "missing");
  }
  Archive a;
  a.config = PoemConfig::FromJson(config.toStringRef(), path + " (embedded config)");
  for (const auto& item : state.toGenericDict()) {
    if (!item.key().isString() || !item.value().isTensor()) {
      throw InputError(path, "state_dict", "text keys and tensor values",
                       item.key().tagKind() + " -> " + item.value().tagKind());
    }
    const std::string& key = item.key().toStringRef();
    CheckTensorInsideRecord(item.value().toTensor(), records, path, key);
    a.tensors[key] = item.value().toTensor();
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
  SaveArchiveAtomically(archive, path);
}

void SaveArchiveAtomically(torch::serialize::OutputArchive& archive,
                           const std::string& path) {
  std::ostringstream bytes;
  archive.save_to(bytes);
  WriteFileAtomically(path, bytes.str());
}

std::string TorchErrorText(const std::exception& error) {
  if (const auto* torch_error = dynamic_cast<const c10::Error*>(&error)) {
    return torch_error->what_without_backtrace();
  }
  return error.what();
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
                            bool as_init_weights) {
  Archive a = ReadArchive(path);
  if (as_init_weights && model->config().mask_head && !a.config.mask_head) {
    a.config.mask_head = true;
    for (const auto& [key, value] : PoemStateDict(model)) {
      if (key.rfind("mask_head.", 0) == 0) a.tensors[key] = value.detach().clone();
    }
  } else if (as_init_weights && !model->config().mask_head && a.config.mask_head) {
    a.config.mask_head = false;
    for (auto it = a.tensors.begin(); it != a.tensors.end();) {
      it = it->first.rfind("mask_head.", 0) == 0 ? a.tensors.erase(it) : std::next(it);
    }
  }
  if (as_init_weights) a.config.num_views = model->config().num_views;
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
