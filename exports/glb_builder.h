#pragma once
// A binary glTF 2.0 file (.glb, Khronos glTF 2.0 spec, "GLB File Format"): the JSON
// document and one binary buffer. Arrays go into the buffer as one bufferView and one
// accessor each (4-byte aligned, little-endian); the caller writes the rest of the
// document (nodes, meshes, skins, animations) into json().

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace handlabel {

class GlbBuilder {
 public:
  GlbBuilder();

  // bufferView targets (glTF: ARRAY_BUFFER for vertex attributes, ELEMENT_ARRAY_BUFFER
  // for indices; none for animation and skin data).
  static constexpr int kNoTarget = 0, kArrayBuffer = 34962, kElementArrayBuffer = 34963;

  // `type`: "SCALAR", "VEC3", "VEC4" or "MAT4" (values.size() a multiple of its width).
  // Float accessors carry per-component min and max (glTF requires them for POSITION
  // and animation inputs). Each returns the accessor's index.
  int AddFloats(const std::vector<float>& values, const std::string& type, int target);
  int AddUnsignedShorts(const std::vector<uint16_t>& values, const std::string& type,
                        int target);
  int AddUnsignedInts(const std::vector<uint32_t>& values, const std::string& type,
                      int target);

  nlohmann::json& json() { return json_; }

  // The .glb bytes: header, JSON chunk (space padded), BIN chunk (zero padded).
  std::string Finish() const;

 private:
  int AddView(const void* data, size_t bytes, int target);
  int AddAccessor(int view, int component_type, size_t count, const std::string& type);

  nlohmann::json json_;
  std::string binary_;
};

}  // namespace handlabel
