#pragma once
// Reads a TFLite flatbuffer (network/detector/tflite_schema.fbs, our subset of TFLite's
// schema) into plain structs: tensors with shapes, types and constant data, and operators
// with the options our interpreter uses. Torch-free, so the fuzz target (fuzz/) builds it
// alone. Every index and size is checked here, so the interpreter can trust the graph:
// the flatbuffers Verifier first, then tensor, buffer and operator indices, shapes
// (non-negative, at most kMaxTfliteElements elements) and constant data sizes.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace handlabel {

// TFLite's TensorType numbers for the types the interpreter runs.
enum class TfliteType : int8_t { kFloat32 = 0, kFloat16 = 1, kInt32 = 2 };

// Largest element count of one tensor (2^28 floats = 1 GiB): larger is a corrupt file.
constexpr int64_t kMaxTfliteElements = int64_t{1} << 28;

struct TfliteTensor {
  std::string name;
  std::vector<int> shape;  // TFLite order (NHWC for images)
  int type = 0;            // TFLite TensorType number (TfliteType for the run ones)
  // Constant data: bytes [data_offset, data_offset + data_size) of TfliteGraph::bytes;
  // has_data is false for activations (the file's empty buffer).
  bool has_data = false;
  size_t data_offset = 0;
  size_t data_size = 0;
  int64_t num_elements() const;
};

// The union of the option fields of the operators we run (TFLite's defaults when the
// file leaves them out).
struct TfliteOpOptions {
  bool padding_valid = false;  // Padding: SAME (false) or VALID (true)
  int stride_w = 1;
  int stride_h = 1;
  int dilation_w = 1;
  int dilation_h = 1;
  int depth_multiplier = 1;
  int filter_w = 1;  // pooling window
  int filter_h = 1;
  int activation =
      0;  // ActivationFunctionType: 0 NONE, 1 RELU, 2 RELU_N1_TO_1, 3 RELU6, 4 TANH
  int axis = 0;                     // CONCATENATION
  bool keep_dims = false;           // MEAN
  bool keep_num_dims = false;       // FULLY_CONNECTED
  int weights_format = 0;           // FULLY_CONNECTED: 0 = DEFAULT
  bool align_corners = false;       // RESIZE_BILINEAR
  bool half_pixel_centers = false;  // RESIZE_BILINEAR
};

struct TfliteOp {
  int code = 0;             // BuiltinOperator number
  std::string name;         // e.g. "CONV_2D"; "CUSTOM:<code>" for custom operators
  std::vector<int> inputs;  // tensor indices; -1 = optional input left out
  std::vector<int> outputs;
  TfliteOpOptions options;
};

struct TfliteGraph {
  std::string bytes;  // the whole file: constant tensor data lives here
  std::vector<TfliteTensor> tensors;
  std::vector<TfliteOp> ops;  // in execution order
  std::vector<int> inputs;    // tensor indices
  std::vector<int> outputs;
  // The bytes of a tensor's constant data (empty when it has none).
  const uint8_t* data(const TfliteTensor& tensor) const;
};

// Parses and verifies the first subgraph of a TFLite file. Throws InputError naming
// `source` and what is wrong. Unsupported operators are not rejected here (the
// interpreter names them).
std::unique_ptr<TfliteGraph> ParseTflite(std::string bytes, const std::string& source);

// The BuiltinOperator name of a code ("CONV_2D"), or "BUILTIN_<n>" when unknown.
std::string TfliteOpName(int code);
// The TensorType name of a type number ("FLOAT16"), or "TYPE_<n>".
std::string TfliteTypeName(int type);

}  // namespace handlabel
