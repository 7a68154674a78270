#pragma once
// Reads the raw tensor bundles written by tests/network/poem/poem_oracle.py:
// NAME.json ({key: {dtype, shape, offset}}) next to NAME.bin (little endian).

#include <torch/torch.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/errors.h"

namespace handlabel::testing {

inline std::map<std::string, torch::Tensor> ReadTensorBundle(const std::string& stem) {
  std::ifstream jf(stem + ".json");
  if (!jf) throw Error("cannot open " + stem + ".json");
  const nlohmann::json manifest = nlohmann::json::parse(jf);
  std::ifstream bf(stem + ".bin", std::ios::binary);
  std::stringstream ss;
  ss << bf.rdbuf();
  const std::string bytes = ss.str();
  std::map<std::string, torch::Tensor> out;
  for (const auto& [key, entry] : manifest.items()) {
    const std::string dtype = entry["dtype"];
    const auto shape = entry["shape"].get<std::vector<int64_t>>();
    const size_t offset = entry["offset"];
    const auto type = dtype == "int64" ? torch::kInt64 : torch::kFloat32;
    torch::Tensor t = torch::empty(shape, type);
    const size_t n = t.numel() * t.element_size();
    if (offset + n > bytes.size()) throw Error("truncated bundle " + stem);
    std::memcpy(t.data_ptr(), bytes.data() + offset, n);
    out[key] = t;
  }
  return out;
}

}  // namespace handlabel::testing
