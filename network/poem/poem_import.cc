#include "network/poem/poem_import.h"

#include <cstring>

#include "core/errors.h"
#include "formats/torch_archive.h"

namespace handlabel {
namespace {

torch::Tensor ToTorch(const NdArray& a, const std::string& where) {
  std::vector<int64_t> shape(a.shape.begin(), a.shape.end());
  switch (a.dtype) {
    case DType::kFloat32: {
      torch::Tensor t = torch::empty(shape, torch::kFloat32);
      std::memcpy(t.data_ptr(), a.data.data(), a.data.size());
      return t;
    }
    case DType::kInt64: {
      torch::Tensor t = torch::empty(shape, torch::kInt64);
      std::memcpy(t.data_ptr(), a.data.data(), a.data.size());
      return t;
    }
    case DType::kFloat64:
    case DType::kFloat16: {
      const std::vector<double> v = a.ToDoubles();
      return torch::tensor(v, torch::kFloat64).reshape(shape).to(torch::kFloat32);
    }
    default:
      if (IsNumeric(a.dtype)) {
        const std::vector<int64_t> v = a.ToInt64s();
        return torch::tensor(v, torch::kInt64).reshape(shape);
      }
      throw InputError(where, "dtype", "a numeric tensor", DTypeName(a.dtype));
  }
}

const torch::Tensor& Need(const std::map<std::string, torch::Tensor>& s,
                          const std::string& key, const std::string& source) {
  auto it = s.find(key);
  if (it == s.end()) {
    throw InputError(source, key, "a POEM (PtEmbedMultiviewStereo) state_dict key",
                     "missing");
  }
  return it->second;
}

int CountIndexed(const std::map<std::string, torch::Tensor>& s, const std::string& prefix,
                 const std::string& suffix) {
  int n = 0;
  while (s.count(prefix + std::to_string(n) + suffix)) ++n;
  return n;
}

}  // namespace

std::map<std::string, torch::Tensor> ReadTorchStateDict(const std::string& path) {
  const TorchArchive archive(path);
  std::map<std::string, torch::Tensor> out;
  for (const auto& [raw_key, array] : archive.Tensors()) {
    std::string key = raw_key;
    for (const char* prefix : {"state_dict.", "module."}) {
      if (key.rfind(prefix, 0) == 0) key = key.substr(std::strlen(prefix));
    }
    out[key] = ToTorch(array, path + ":" + raw_key);
  }
  return out;
}

PoemConfig InferPoemConfig(const std::map<std::string, torch::Tensor>& s,
                           const PoemConfig& base, const std::string& source) {
  PoemConfig c = base;
  c.backbone_width = Need(s, "img_backbone.conv1.weight", source).size(0);
  const int layer3 = CountIndexed(s, "img_backbone.layer3.", ".conv1.weight");
  if (layer3 == 2) {
    c.backbone = "resnet18";
  } else if (layer3 == 6) {
    c.backbone = "resnet34";
  } else {
    throw InputError(source, "img_backbone.layer3", "2 (ResNet18) or 6 (ResNet34) blocks",
                     std::to_string(layer3));
  }
  c.embed_dim = Need(s, "ptEmb_head.input_proj.weight", source).size(0);
  c.depth_bins = Need(s, "ptEmb_head.position_encoder.0.weight", source).size(1) / 3;
  c.transformer_dim =
      Need(s, "ptEmb_head.transformer.feats_self_attn.fc1.weight", source).size(0);
  c.num_decoder_blocks = CountIndexed(s, "ptEmb_head.reg_branches.", ".0.weight");
  return c;
}

PoemModel ImportReleasedPoemCheckpoint(const std::string& path, const PoemConfig& config,
                                       StateDictReport* report) {
  config.Check("POEM config");
  const std::map<std::string, torch::Tensor> state = ReadTorchStateDict(path);
  const PoemConfig found = InferPoemConfig(state, config, path);
  const std::vector<std::string> diff = config.Differences(found);
  if (!diff.empty()) {
    std::string got;
    for (const auto& d : diff) got += (got.empty() ? "" : "; ") + d;
    throw InputError(path, "architecture", "weights for the requested POEM config",
                     "weights of another size (config vs checkpoint: " + got + ")");
  }
  PoemModel model(config);
  StateDictReport r = LoadPoemStateDict(model, state, path, {"mano_layer."});
  if (report) *report = r;
  return model;
}

}  // namespace handlabel
