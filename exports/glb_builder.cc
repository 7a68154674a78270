#include "exports/glb_builder.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr int kUnsignedShort = 5123, kUnsignedInt = 5125, kFloat = 5126;

int Width(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  HL_CHECK(type == "MAT4", "a glTF accessor type");
  return 16;
}

void AppendLittleEndian(uint32_t value, std::string* out) {
  for (int k = 0; k < 4; ++k)
    out->push_back(static_cast<char>((value >> (8 * k)) & 0xFF));
}

}  // namespace

GlbBuilder::GlbBuilder() {
  json_ = {{"asset", {{"version", "2.0"}, {"generator", "handlabel export"}}},
           {"bufferViews", nlohmann::json::array()},
           {"accessors", nlohmann::json::array()}};
}

int GlbBuilder::AddView(const void* data, size_t bytes, int target) {
  while (binary_.size() % 4 != 0) binary_.push_back('\0');
  nlohmann::json view = {
      {"buffer", 0}, {"byteOffset", binary_.size()}, {"byteLength", bytes}};
  if (target != kNoTarget) view["target"] = target;
  binary_.append(static_cast<const char*>(data), bytes);
  json_["bufferViews"].push_back(view);
  return static_cast<int>(json_["bufferViews"].size()) - 1;
}

int GlbBuilder::AddAccessor(int view, int component_type, size_t count,
                            const std::string& type) {
  json_["accessors"].push_back({{"bufferView", view},
                                {"componentType", component_type},
                                {"count", count},
                                {"type", type}});
  return static_cast<int>(json_["accessors"].size()) - 1;
}

int GlbBuilder::AddFloats(const std::vector<float>& values, const std::string& type,
                          int target) {
  const int width = Width(type);
  HL_CHECK(!values.empty() && values.size() % width == 0, "whole glTF elements");
  std::vector<float> min(width, std::numeric_limits<float>::max());
  std::vector<float> max(width, std::numeric_limits<float>::lowest());
  for (size_t i = 0; i < values.size(); ++i) {
    min[i % width] = std::min(min[i % width], values[i]);
    max[i % width] = std::max(max[i % width], values[i]);
  }
  const int view = AddView(values.data(), values.size() * sizeof(float), target);
  const int accessor = AddAccessor(view, kFloat, values.size() / width, type);
  json_["accessors"][accessor]["min"] = min;
  json_["accessors"][accessor]["max"] = max;
  return accessor;
}

int GlbBuilder::AddUnsignedShorts(const std::vector<uint16_t>& values,
                                  const std::string& type, int target) {
  HL_CHECK(!values.empty() && values.size() % Width(type) == 0, "whole glTF elements");
  const int view = AddView(values.data(), values.size() * sizeof(uint16_t), target);
  return AddAccessor(view, kUnsignedShort, values.size() / Width(type), type);
}

int GlbBuilder::AddUnsignedInts(const std::vector<uint32_t>& values,
                                const std::string& type, int target) {
  HL_CHECK(!values.empty() && values.size() % Width(type) == 0, "whole glTF elements");
  const int view = AddView(values.data(), values.size() * sizeof(uint32_t), target);
  return AddAccessor(view, kUnsignedInt, values.size() / Width(type), type);
}

std::string GlbBuilder::Finish() const {
  nlohmann::json document = json_;
  std::string bin = binary_;
  while (bin.size() % 4 != 0) bin.push_back('\0');
  document["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
  std::string text = document.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  std::string out = "glTF";
  AppendLittleEndian(2, &out);  // version
  AppendLittleEndian(static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()), &out);
  AppendLittleEndian(static_cast<uint32_t>(text.size()), &out);
  out += "JSON";
  out += text;
  AppendLittleEndian(static_cast<uint32_t>(bin.size()), &out);
  out.append("BIN\0", 4);
  out += bin;
  return out;
}

}  // namespace handlabel
