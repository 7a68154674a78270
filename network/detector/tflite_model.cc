// The LibTorch interpreter behind network/detector/tflite_model.h.
//
// Loading turns every operator into a step (network/detector/tflite_steps.h), then runs
// the graph once on zeros and checks each result's shape against the shape the file
// declares, so semantic mismatches and malformed graphs fail at load, naming the
// operator.

#include <omp.h>
#include <torch/torch.h>

#include <algorithm>
#include <cstring>
#include <sstream>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/option_checks.h"
#include "network/detector/tflite_model.h"
#include "network/detector/tflite_reader.h"
#include "network/detector/tflite_steps.h"

namespace handlabel {
namespace {

using tflite::InTfliteOrder;
using tflite::ShapeString;
using tflite::ToInt64;
using tflite::Value;
using torch::Tensor;

// LibTorch's intra-op thread count for the calling thread only, for one call. The count
// (OpenMP's nthreads setting) is kept per thread, so callers that detect frames or views
// in parallel each get theirs, and no process-wide at::set_num_threads races between
// them or changes what the POEM network's threads use.
class CallingThreadIntraOpThreads {
 public:
  explicit CallingThreadIntraOpThreads(int threads) {
    if (threads <= 0) return;
    // Also runs ATen's first-use set-up of this thread's count, which would otherwise
    // replace ours at the first operator.
    previous_ = at::get_num_threads();
    if (previous_ != threads) omp_set_num_threads(threads);
  }
  ~CallingThreadIntraOpThreads() {
    if (previous_ > 0) omp_set_num_threads(previous_);
  }
  CallingThreadIntraOpThreads(const CallingThreadIntraOpThreads&) = delete;
  CallingThreadIntraOpThreads& operator=(const CallingThreadIntraOpThreads&) = delete;

 private:
  int previous_ = 0;
};

class Interpreter : public TfliteModel {
 public:
  Interpreter(std::unique_ptr<TfliteGraph> graph, const std::string& source,
              int num_threads);
  const std::vector<TfliteTensorInfo>& inputs() const override { return inputs_; }
  const std::vector<TfliteTensorInfo>& outputs() const override { return outputs_; }
  std::vector<std::string> op_names() const override { return op_names_; }
  std::vector<std::vector<float>> Run(
      const std::vector<std::vector<float>>& inputs) const override;

 private:
  void CheckInputs(const std::vector<std::vector<float>>& inputs) const;
  std::vector<Value> Execute(const std::vector<std::vector<float>>& inputs,
                             bool check_shapes) const;

  std::unique_ptr<TfliteGraph> graph_;
  std::string source_;
  int num_threads_ = 0;  // TfliteModelOptions::num_threads
  std::vector<TfliteTensorInfo> inputs_, outputs_;
  std::vector<std::string> op_names_;
  tflite::Program program_;
};

Tensor LoadConstant(const TfliteGraph& g, const TfliteTensor& t) {
  const auto shape = ToInt64(t.shape);
  const auto type = t.type == 0   ? torch::kFloat32
                    : t.type == 1 ? torch::kFloat16
                                  : torch::kInt32;
  Tensor out = torch::empty(shape, torch::TensorOptions().dtype(type));
  std::memcpy(out.data_ptr(), g.data(t), t.data_size);  // the reader checked the size
  return out;
}

// A weight that is NaN or infinite makes every answer NaN: a palm model with NaN
// weights found "no hand" in every image and replaced good detections.
void RequireFiniteWeights(const Tensor& weights, size_t index, const TfliteTensor& t,
                          const std::string& source) {
  const Tensor bad = torch::logical_not(torch::isfinite(weights)).flatten();
  const int64_t count = bad.sum().item<int64_t>();
  if (count == 0) return;
  const int64_t first = bad.nonzero()[0][0].item<int64_t>();
  throw InputError(
      source, "tensor " + std::to_string(index) + " (" + t.name + ")", "finite weights",
      std::to_string(count) + " of " + std::to_string(weights.numel()) +
          " values NaN or infinite, the first at element " + std::to_string(first) +
          " (" + std::to_string(weights.flatten()[first].item<float>()) + ")");
}

std::vector<TfliteTensorInfo> TensorInfos(const TfliteGraph& g,
                                          const std::vector<int>& ids) {
  std::vector<TfliteTensorInfo> infos;
  for (int id : ids) infos.push_back({g.tensors[id].name, g.tensors[id].shape});
  return infos;
}

Interpreter::Interpreter(std::unique_ptr<TfliteGraph> graph, const std::string& source,
                         int num_threads)
    : graph_(std::move(graph)), source_(source), num_threads_(num_threads) {
  const TfliteGraph& g = *graph_;
  for (const TfliteOp& op : g.ops) {
    if (std::find(op_names_.begin(), op_names_.end(), op.name) == op_names_.end()) {
      op_names_.push_back(op.name);
    }
  }
  // Types: constants FLOAT32/FLOAT16/INT32; everything computed FLOAT32.
  program_.constants.resize(g.tensors.size());
  for (size_t i = 0; i < g.tensors.size(); ++i) {
    const TfliteTensor& t = g.tensors[i];
    const bool known = t.type == 0 || (t.has_data && (t.type == 1 || t.type == 2));
    if (!known) {
      throw InputError(source_, "tensor " + std::to_string(i) + " (" + t.name + ") type",
                       t.has_data ? "FLOAT32, FLOAT16 or INT32 constant data" : "FLOAT32",
                       TfliteTypeName(t.type));
    }
    if (t.has_data) program_.constants[i] = LoadConstant(g, t);
    if (t.has_data && t.type != 2)
      RequireFiniteWeights(*program_.constants[i], i, t, source_);
  }
  for (int id : g.inputs) {
    if (program_.constants[id]) {
      throw InputError(source_, "subgraph input " + g.tensors[id].name,
                       "a tensor without data", "a constant");
    }
  }
  inputs_ = TensorInfos(g, g.inputs);
  outputs_ = TensorInfos(g, g.outputs);
  try {
    torch::InferenceMode guard;
    tflite::BuildSteps(g, source_, &program_);
  } catch (const c10::Error& e) {  // a constant whose shape an operator cannot use
    throw InputError(source_, "operators", "constants of the shapes the operators take",
                     std::string(e.what_without_backtrace()));
  }
  // One run on zeros: every result must have the shape the file declares.
  std::vector<std::vector<float>> zeros;
  for (const auto& info : inputs_) zeros.emplace_back(info.num_elements(), 0.0f);
  const std::vector<Value> values = Execute(zeros, /*check_shapes=*/true);
  for (int id : g.outputs) {
    if (!values[id].t.defined()) {
      throw InputError(source_, "subgraph output " + g.tensors[id].name,
                       "a tensor computed by an operator or constant", "never written");
    }
  }
}

void Interpreter::CheckInputs(const std::vector<std::vector<float>>& inputs) const {
  if (inputs.size() != inputs_.size()) {
    throw InputError(source_, "inputs", std::to_string(inputs_.size()) + " input tensors",
                     std::to_string(inputs.size()));
  }
  for (size_t i = 0; i < inputs.size(); ++i) {
    const int64_t want = inputs_[i].num_elements();
    if (static_cast<int64_t>(inputs[i].size()) != want) {
      throw InputError(
          source_, "input " + std::to_string(i) + " (" + inputs_[i].name + ")",
          std::to_string(want) + " floats (" + ShapeString(inputs_[i].shape) + ")",
          std::to_string(inputs[i].size()));
    }
  }
}

std::vector<Value> Interpreter::Execute(const std::vector<std::vector<float>>& inputs,
                                        bool check_shapes) const {
  CheckInputs(inputs);
  torch::InferenceMode guard;
  const CallingThreadIntraOpThreads threads(num_threads_);
  const TfliteGraph& g = *graph_;
  std::vector<Value> values(g.tensors.size());
  for (size_t i = 0; i < program_.constants.size(); ++i) {
    if (program_.constants[i]) values[i] = {*program_.constants[i], false};
  }
  for (size_t i = 0; i < inputs.size(); ++i) {
    const int id = g.inputs[i];
    Tensor t = torch::from_blob(const_cast<float*>(inputs[i].data()),
                                ToInt64(g.tensors[id].shape), torch::kFloat32);
    values[id] = {t, false};  // read only: no step writes into its inputs
  }
  for (size_t s = 0; s < program_.steps.size(); ++s) {
    const TfliteOp& op = g.ops[program_.step_op[s]];
    if (!check_shapes) {
      program_.steps[s](values);
      continue;
    }
    const std::string where =
        "operator " + std::to_string(program_.step_op[s]) + " (" + op.name + ")";
    try {
      program_.steps[s](values);
    } catch (const c10::Error& e) {
      throw InputError(source_, where, "tensors this operator accepts",
                       std::string(e.what_without_backtrace()));
    }
    const TfliteTensor& out = g.tensors[op.outputs[0]];
    const Tensor result = InTfliteOrder(values[op.outputs[0]]);
    if (result.sizes() != c10::IntArrayRef(ToInt64(out.shape))) {
      std::ostringstream got;
      got << result.sizes();
      throw InputError(source_, where + " output " + out.name,
                       "the declared shape " + ShapeString(out.shape), got.str());
    }
  }
  return values;
}

std::vector<std::vector<float>> Interpreter::Run(
    const std::vector<std::vector<float>>& inputs) const {
  std::vector<Value> values = Execute(inputs, /*check_shapes=*/false);
  std::vector<std::vector<float>> outputs;
  for (int id : graph_->outputs) {
    if (!values[id].t.defined()) {
      throw InputError(source_, "output " + graph_->tensors[id].name,
                       "a tensor computed by the graph", "never written");
    }
    Tensor t = InTfliteOrder(values[id]).contiguous().to(torch::kFloat32);
    outputs.emplace_back(t.data_ptr<float>(), t.data_ptr<float>() + t.numel());
  }
  return outputs;
}

}  // namespace

int64_t TfliteTensorInfo::num_elements() const {
  int64_t n = 1;
  for (int d : shape) n *= d;
  return n;
}

void TfliteModelOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "num_threads", num_threads, 0,
                 ">= 0 (0 = the calling thread's setting)");
}

std::unique_ptr<TfliteModel> TfliteModel::FromBytes(const std::string& bytes,
                                                    const std::string& source,
                                                    const TfliteModelOptions& options) {
  options.Check(source);
  return std::make_unique<Interpreter>(ParseTflite(bytes, source), source,
                                       options.num_threads);
}

std::unique_ptr<TfliteModel> TfliteModel::Load(const std::string& path,
                                               const TfliteModelOptions& options) {
  return FromBytes(ReadFileBytes(path, ".tflite file"), path, options);
}

}  // namespace handlabel
