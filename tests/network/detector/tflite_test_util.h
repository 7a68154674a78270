#pragma once
// Tiny TFLite models built in memory with flatbuffers' builder API (our schema subset,
// network/detector/tflite_schema.fbs), and plain-loop NHWC helpers, for the interpreter
// tests.

#include <flatbuffers/flatbuffers.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "network/detector/tflite_schema_generated.h"

namespace handlabel::testing_tflite {

namespace fb = handlabel::tflite_fb;

// Round-trips a float through IEEE half precision (round to nearest even), independent
// of LibTorch: the value an fp16 weight stores.
inline uint16_t FloatToHalf(float f) {
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint32_t sign = (x >> 16) & 0x8000;
  int32_t exponent = static_cast<int32_t>((x >> 23) & 0xff) - 127 + 15;
  uint32_t mantissa = x & 0x7fffff;
  if (exponent <= 0) return static_cast<uint16_t>(sign);  // tests use normal values only
  if (exponent >= 31) return static_cast<uint16_t>(sign | 0x7c00);
  uint32_t half = sign | (static_cast<uint32_t>(exponent) << 10) | (mantissa >> 13);
  const uint32_t rest = mantissa & 0x1fff;
  if (rest > 0x1000 || (rest == 0x1000 && (half & 1))) ++half;
  return static_cast<uint16_t>(half);
}
inline float HalfToFloat(uint16_t h) {
  const uint32_t sign = (h & 0x8000u) << 16;
  const uint32_t exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  uint32_t x = sign;
  if (exponent != 0) x |= ((exponent - 15 + 127) << 23) | (mantissa << 13);
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

class TfliteBuilder {
 public:
  TfliteBuilder() { buffers_.push_back(fb::CreateBuffer(fbb_)); }  // buffer 0: empty
  flatbuffers::FlatBufferBuilder& fbb() { return fbb_; }

  // An activation tensor (no data).
  int Tensor(const std::vector<int>& shape, const std::string& name = "",
             fb::TensorType type = fb::TensorType_FLOAT32) {
    tensors_.push_back(
        {shape, name.empty() ? "t" + std::to_string(tensors_.size()) : name, type, 0});
    return static_cast<int>(tensors_.size()) - 1;
  }
  int Constant(const std::vector<int>& shape, const std::vector<float>& values) {
    return WithData(shape, fb::TensorType_FLOAT32, values.data(), values.size() * 4);
  }
  int ConstantInt(const std::vector<int>& shape, const std::vector<int32_t>& values) {
    return WithData(shape, fb::TensorType_INT32, values.data(), values.size() * 4);
  }
  int ConstantHalf(const std::vector<int>& shape, const std::vector<float>& values) {
    std::vector<uint16_t> halves;
    for (float v : values) halves.push_back(FloatToHalf(v));
    return WithData(shape, fb::TensorType_FLOAT16, halves.data(), halves.size() * 2);
  }
  // A tensor with raw bytes of any type (for malformed-file tests).
  int WithData(const std::vector<int>& shape, fb::TensorType type, const void* data,
               size_t size) {
    fbb_.ForceVectorAlignment(size, 1, 16);
    auto bytes = fbb_.CreateVector(static_cast<const uint8_t*>(data), size);
    buffers_.push_back(fb::CreateBuffer(fbb_, bytes));
    tensors_.push_back({shape, "c" + std::to_string(tensors_.size()), type,
                        static_cast<uint32_t>(buffers_.size() - 1)});
    return static_cast<int>(tensors_.size()) - 1;
  }
  void SetBufferIndex(int tensor, uint32_t buffer) { tensors_[tensor].buffer = buffer; }

  void Op(int code, const std::vector<int>& inputs, const std::vector<int>& outputs,
          fb::BuiltinOptions type = fb::BuiltinOptions_NONE,
          flatbuffers::Offset<void> options = 0) {
    ops_.push_back({OpcodeIndex(code), inputs, outputs, type, options});
  }

  std::string Finish(const std::vector<int>& inputs, const std::vector<int>& outputs) {
    std::vector<flatbuffers::Offset<fb::Tensor>> tensors;
    for (const auto& t : tensors_) {
      tensors.push_back(fb::CreateTensor(fbb_, fbb_.CreateVector(t.shape), t.type,
                                         t.buffer, fbb_.CreateString(t.name)));
    }
    std::vector<flatbuffers::Offset<fb::Operator>> ops;
    for (const auto& o : ops_) {
      ops.push_back(fb::CreateOperator(fbb_, o.opcode_index, fbb_.CreateVector(o.inputs),
                                       fbb_.CreateVector(o.outputs), o.type, o.options));
    }
    std::vector<flatbuffers::Offset<fb::OperatorCode>> codes;
    for (int c : codes_) {
      codes.push_back(
          fb::CreateOperatorCode(fbb_, static_cast<int8_t>(std::min(c, 127)), 0, 1, c));
    }
    auto graph =
        fb::CreateSubGraph(fbb_, fbb_.CreateVector(tensors), fbb_.CreateVector(inputs),
                           fbb_.CreateVector(outputs), fbb_.CreateVector(ops));
    std::vector<flatbuffers::Offset<fb::SubGraph>> graphs{graph};
    auto model =
        fb::CreateModel(fbb_, 3, fbb_.CreateVector(codes), fbb_.CreateVector(graphs), 0,
                        fbb_.CreateVector(buffers_));
    fb::FinishModelBuffer(fbb_, model);
    return std::string(reinterpret_cast<const char*>(fbb_.GetBufferPointer()),
                       fbb_.GetSize());
  }

 private:
  struct TensorSpec {
    std::vector<int> shape;
    std::string name;
    fb::TensorType type;
    uint32_t buffer;
  };
  struct OpSpec {
    uint32_t opcode_index;
    std::vector<int> inputs, outputs;
    fb::BuiltinOptions type;
    flatbuffers::Offset<void> options;
  };
  uint32_t OpcodeIndex(int code) {
    for (size_t i = 0; i < codes_.size(); ++i) {
      if (codes_[i] == code) return static_cast<uint32_t>(i);
    }
    codes_.push_back(code);
    return static_cast<uint32_t>(codes_.size() - 1);
  }

  flatbuffers::FlatBufferBuilder fbb_;
  std::vector<flatbuffers::Offset<fb::Buffer>> buffers_;
  std::vector<TensorSpec> tensors_;
  std::vector<OpSpec> ops_;
  std::vector<int> codes_;
};

// Uniform random floats in [lo, hi) from a seeded generator.
inline std::vector<float> RandomFloats(size_t n, std::mt19937& rng, float lo = -1,
                                       float hi = 1) {
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = u(rng);
  return v;
}

// Row-major NHWC index.
inline size_t Nhwc(int h, int w, int c, int width, int channels) {
  return (static_cast<size_t>(h) * width + w) * channels + c;
}

}  // namespace handlabel::testing_tflite
