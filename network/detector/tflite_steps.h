#pragma once
// The operator steps of the TFLite interpreter (network/detector/tflite_model.cc): every
// operator of a graph becomes a closure over LibTorch with its weights already
// dequantised and permuted into LibTorch's layout. Internal to network/ (it includes
// LibTorch).
//
// Layout: TFLite is NHWC; LibTorch's convolutions are NCHW. Rank-4 activations made by
// convolutions and pools stay NCHW between operators (Value::nchw) and are permuted to
// TFLite order only where an operator's meaning depends on the memory order (RESHAPE,
// FULLY_CONNECTED, outputs).

#include <torch/torch.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "network/detector/tflite_reader.h"

namespace handlabel::tflite {

// An activation: rank-4 tensors may be held NCHW (nchw = true); all others are in
// TFLite's order.
struct Value {
  torch::Tensor t;
  bool nchw = false;
};

using Step = std::function<void(std::vector<Value>& values)>;

// What the interpreter runs: per tensor its constant data (FLOAT32/FLOAT16/INT32 as in
// the file; DEQUANTIZE adds float copies), and the steps in graph order.
struct Program {
  std::vector<std::optional<torch::Tensor>> constants;
  std::vector<Step> steps;
  std::vector<int> step_op;  // the operator index of each step
};

// Appends a step per operator of `graph` to program->steps (program->constants must
// hold the file's constants). Throws InputError naming `source` and the operator.
void BuildSteps(const TfliteGraph& graph, const std::string& source, Program* program);

// "1x224x224x3" ("scalar" for rank 0).
std::string ShapeString(const std::vector<int>& shape);
std::vector<int64_t> ToInt64(const std::vector<int>& v);
// A value in TFLite's (NHWC) order.
torch::Tensor InTfliteOrder(const Value& v);

}  // namespace handlabel::tflite
