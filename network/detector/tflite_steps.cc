#include "network/detector/tflite_steps.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>

#include "core/errors.h"

namespace handlabel::tflite {

using torch::Tensor;

std::string ShapeString(const std::vector<int>& shape) {
  std::ostringstream s;
  for (size_t i = 0; i < shape.size(); ++i) s << (i ? "x" : "") << shape[i];
  return shape.empty() ? "scalar" : s.str();
}

std::vector<int64_t> ToInt64(const std::vector<int>& v) { return {v.begin(), v.end()}; }

Tensor InTfliteOrder(const Value& v) { return v.nchw ? v.t.permute({0, 2, 3, 1}) : v.t; }

namespace {

constexpr int kAdd = 0, kConcatenation = 2, kConv2d = 3, kDepthwiseConv2d = 4,
              kDequantize = 6, kFullyConnected = 9, kLogistic = 14, kMaxPool2d = 17,
              kMul = 18, kReshape = 22, kResizeBilinear = 23, kPad = 34, kMean = 40,
              kSub = 41, kDiv = 42, kPrelu = 54;

const char* const kSupportedOps =
    "ADD, CONCATENATION, CONV_2D, DEPTHWISE_CONV_2D, DEQUANTIZE, DIV, FULLY_CONNECTED, "
    "LOGISTIC, MAX_POOL_2D, MEAN, MUL, PAD, PRELU, RESHAPE, RESIZE_BILINEAR, SUB";

// NCHW for rank-4 values.
Tensor InNchw(const Value& v) {
  TORCH_CHECK(v.t.dim() == 4, "expected a rank-4 tensor, got rank ", v.t.dim());
  return v.nchw ? v.t : v.t.permute({0, 3, 1, 2});
}
// A TFLite-order operand broadcast against an NCHW rank-4 value: pad its shape with
// leading ones to rank 4 (numpy broadcasting), then permute like the value.
Tensor BroadcastToNchw(const Value& v) {
  if (v.nchw) return v.t;
  TORCH_CHECK(v.t.dim() <= 4, "cannot broadcast rank ", v.t.dim(), " against rank 4");
  std::vector<int64_t> shape(4 - v.t.dim(), 1);
  for (int64_t d : v.t.sizes()) shape.push_back(d);
  return v.t.reshape(shape).permute({0, 3, 1, 2});
}

// The NCHW dimension of a TFLite-order (NHWC) dimension of a rank-4 tensor.
int64_t NchwDim(int64_t nhwc_dim) {
  static const int64_t kMap[] = {0, 2, 3, 1};
  return kMap[nhwc_dim];
}

Tensor Activate(Tensor x, int activation) {
  switch (activation) {
    case 0:
      return x;
    case 1:
      return torch::relu(x);
    case 2:
      return torch::clamp(x, -1.0, 1.0);
    case 3:
      return torch::clamp(x, 0.0, 6.0);
    case 4:
      return torch::tanh(x);
    default:
      TORCH_CHECK(false, "unsupported fused activation ", activation);
  }
}

// TFLite's padding of one spatial axis: total = max((out - 1) * stride + k_eff - in, 0),
// the smaller half before (ComputePaddingHeightWidth).
struct AxisPadding {
  int64_t before = 0, after = 0, out = 0;
};
AxisPadding PadAxis(int64_t in, int64_t kernel, int64_t stride, int64_t dilation,
                    bool valid) {
  const int64_t k_eff = (kernel - 1) * dilation + 1;
  AxisPadding p;
  p.out = valid ? (in - k_eff + stride) / stride : (in + stride - 1) / stride;
  if (valid) return p;
  const int64_t total = std::max<int64_t>((p.out - 1) * stride + k_eff - in, 0);
  p.before = total / 2;
  p.after = total - p.before;
  return p;
}

// Pads H and W of an NCHW tensor when TFLite's SAME padding is asymmetric (or always,
// for pools, whose padded cells must never win: value -inf).
struct SpatialPadding {
  AxisPadding h, w;
  bool symmetric() const { return h.before == h.after && w.before == w.after; }
};
Tensor PadSpatial(const Tensor& x, const SpatialPadding& p, double value) {
  return torch::constant_pad_nd(x, {p.w.before, p.w.after, p.h.before, p.h.after}, value);
}

// Turns operators into steps; throws InputError naming the operator.
class Builder {
 public:
  Builder(const TfliteGraph& graph, const std::string& source, Program* program)
      : g_(graph), source_(source), p_(*program) {}
  void BuildAll();

 private:
  [[noreturn]] void Fail(const std::string& field, const std::string& expected,
                         const std::string& got) const {
    throw InputError(
        source_,
        "operator " + std::to_string(op_index_) + " (" + op_->name + ") " + field,
        expected, got);
  }
  const TfliteTensor& InTensor(size_t i) const {
    if (i >= op_->inputs.size() || op_->inputs[i] < 0) {
      Fail("input " + std::to_string(i), "a tensor", "missing");
    }
    return g_.tensors[op_->inputs[i]];
  }
  bool HasInput(size_t i) const { return i < op_->inputs.size() && op_->inputs[i] >= 0; }
  int In(size_t i) const {
    InTensor(i);
    return op_->inputs[i];
  }
  int Out() const { return op_->outputs[0]; }
  const std::vector<int>& InShape(size_t i) const { return InTensor(i).shape; }
  const Tensor& Constant(size_t i) const {
    const int index = In(i);
    if (!p_.constants[index]) {
      Fail("input " + std::to_string(i) + " (" + g_.tensors[index].name + ")",
           "constant data", "a computed tensor");
    }
    return *p_.constants[index];
  }
  std::vector<int64_t> ConstantInts(size_t i) const {
    Tensor c = Constant(i).to(torch::kInt64).flatten();
    return std::vector<int64_t>(c.data_ptr<int64_t>(), c.data_ptr<int64_t>() + c.numel());
  }
  void ExpectArity(size_t min_inputs, size_t max_inputs) const {
    if (op_->inputs.size() < min_inputs || op_->inputs.size() > max_inputs ||
        op_->outputs.size() != 1) {
      Fail("inputs/outputs",
           std::to_string(min_inputs) + ".." + std::to_string(max_inputs) +
               " inputs and 1 output",
           std::to_string(op_->inputs.size()) + " inputs, " +
               std::to_string(op_->outputs.size()) + " outputs");
    }
  }
  void ExpectRank(size_t input, size_t rank) const {
    if (InShape(input).size() != rank) {
      Fail("input " + std::to_string(input) + " shape", "rank " + std::to_string(rank),
           ShapeString(InShape(input)));
    }
  }
  void ExpectActivation() const {
    if (op_->options.activation < 0 || op_->options.activation > 4) {
      Fail("fused_activation_function", "NONE, RELU, RELU_N1_TO_1, RELU6 or TANH",
           std::to_string(op_->options.activation));
    }
  }
  std::optional<Tensor> BiasOrNone(size_t i) const {
    return HasInput(i) ? std::optional<Tensor>(Constant(i)) : std::nullopt;
  }

  void Dequantize();
  Step Conv(bool depthwise);
  Step FullyConnected();
  Step Binary(int code);
  Step Mean();
  Step Logistic();
  Step Prelu();
  Step Pad();
  Step MaxPool();
  Step ResizeBilinear();
  Step Reshape();
  Step Concatenation();

  const TfliteGraph& g_;
  const std::string& source_;
  Program& p_;
  const TfliteOp* op_ = nullptr;
  int op_index_ = 0;
};

void Builder::Dequantize() {
  ExpectArity(1, 1);
  const int in = In(0);
  if (!p_.constants[in] || g_.tensors[in].type != 1) {
    Fail("input 0", "a constant FLOAT16 tensor (fp16 weights)",
         p_.constants[in] ? TfliteTypeName(g_.tensors[in].type) : "a computed tensor");
  }
  p_.constants[Out()] = p_.constants[in]->to(torch::kFloat32);
}

Step Builder::Conv(bool depthwise) {
  ExpectArity(2, 3);
  ExpectRank(0, 4);
  ExpectRank(1, 4);
  ExpectActivation();
  const auto& o = op_->options;
  const auto& in = InShape(0);
  const Tensor& filter = Constant(1);
  // TFLite filters: CONV_2D [O, KH, KW, I]; DEPTHWISE [1, KH, KW, I * M].
  Tensor weight = depthwise ? filter.permute({3, 0, 1, 2}).contiguous()
                            : filter.permute({0, 3, 1, 2}).contiguous();
  const int64_t in_channels = in[3];
  if (in_channels < 1) Fail("input shape", "at least one channel", ShapeString(in));
  const int64_t filter_in = depthwise ? 1 : filter.size(3);
  const int64_t groups =
      depthwise ? in_channels : in_channels / std::max<int64_t>(filter_in, 1);
  if (groups < 1 || groups * filter_in != in_channels ||
      (depthwise && filter.size(3) % in_channels != 0)) {
    Fail("filter shape", "channels matching the input's " + std::to_string(in_channels),
         ShapeString(InShape(1)));
  }
  if (o.stride_h < 1 || o.stride_w < 1 || o.dilation_h < 1 || o.dilation_w < 1) {
    Fail("stride/dilation", "positive values",
         std::to_string(o.stride_h) + "," + std::to_string(o.stride_w) + "," +
             std::to_string(o.dilation_h) + "," + std::to_string(o.dilation_w));
  }
  SpatialPadding pad{
      PadAxis(in[1], weight.size(2), o.stride_h, o.dilation_h, o.padding_valid),
      PadAxis(in[2], weight.size(3), o.stride_w, o.dilation_w, o.padding_valid)};
  std::optional<Tensor> bias = BiasOrNone(2);
  const int x = In(0), out = Out(), activation = o.activation;
  const std::vector<int64_t> stride{o.stride_h, o.stride_w},
      dilation{o.dilation_h, o.dilation_w};
  return [=](std::vector<Value>& v) {
    Tensor input = InNchw(v[x]);
    std::vector<int64_t> padding{pad.h.before, pad.w.before};
    if (!pad.symmetric()) {
      input = PadSpatial(input, pad, 0.0);
      padding = {0, 0};
    }
    Tensor y = torch::conv2d(input, weight, bias ? *bias : Tensor(), stride, padding,
                             dilation, groups);
    v[out] = {Activate(y, activation), true};
  };
}

Step Builder::FullyConnected() {
  ExpectArity(2, 3);
  ExpectActivation();
  if (op_->options.weights_format != 0) {
    Fail("weights_format", "DEFAULT (0)", std::to_string(op_->options.weights_format));
  }
  Tensor weight = Constant(1);  // [out, in]
  if (weight.dim() != 2) Fail("weights shape", "rank 2", ShapeString(InShape(1)));
  const int64_t in_features = weight.size(1);
  const auto& in = InShape(0);
  int64_t in_elements = 1;
  for (int d : in) in_elements *= d;
  if (in_features == 0 || in_elements % in_features != 0) {
    Fail("input shape",
         "a multiple of the weights' " + std::to_string(in_features) + " columns",
         ShapeString(in));
  }
  std::vector<int64_t> out_shape = ToInt64(in);
  if (op_->options.keep_num_dims && !out_shape.empty()) {
    out_shape.back() = weight.size(0);
  } else {
    out_shape = {in_elements / in_features, weight.size(0)};
  }
  std::optional<Tensor> bias = BiasOrNone(2);
  const int x = In(0), out = Out(), activation = op_->options.activation;
  return [=](std::vector<Value>& v) {
    Tensor rows = InTfliteOrder(v[x]).reshape({-1, in_features});
    Tensor y = torch::linear(rows, weight, bias ? *bias : Tensor()).reshape(out_shape);
    v[out] = {Activate(y, activation), false};
  };
}

Step Builder::Binary(int code) {
  ExpectArity(2, 2);
  ExpectActivation();
  const int a = In(0), b = In(1), out = Out(), activation = op_->options.activation;
  return [=](std::vector<Value>& v) {
    const Value& va = v[a];
    const Value& vb = v[b];
    const bool nchw = va.nchw || vb.nchw;
    Tensor ta = nchw ? BroadcastToNchw(va) : va.t;
    Tensor tb = nchw ? BroadcastToNchw(vb) : vb.t;
    Tensor y = code == kAdd   ? ta + tb
               : code == kSub ? ta - tb
               : code == kMul ? ta * tb
                              : ta / tb;
    v[out] = {Activate(y, activation), nchw};
  };
}

Step Builder::Mean() {
  ExpectArity(2, 2);
  const int64_t rank = static_cast<int64_t>(InShape(0).size());
  std::vector<int64_t> axes = ConstantInts(1);
  for (int64_t& axis : axes) {
    if (axis < -rank || axis >= rank) {
      Fail("axes",
           "values in [-" + std::to_string(rank) + ", " + std::to_string(rank) + ")",
           std::to_string(axis));
    }
    if (axis < 0) axis += rank;
  }
  std::sort(axes.begin(), axes.end());
  axes.erase(std::unique(axes.begin(), axes.end()), axes.end());
  const bool keep_dims = op_->options.keep_dims;
  const int x = In(0), out = Out();
  return [=](std::vector<Value>& v) {
    const Value& in = v[x];
    if (!in.nchw) {
      v[out] = {torch::mean(in.t, axes, keep_dims), false};
      return;
    }
    std::vector<int64_t> nchw_axes;
    for (int64_t axis : axes) nchw_axes.push_back(NchwDim(axis));
    Tensor y = torch::mean(in.t, nchw_axes, /*keepdim=*/true);
    if (keep_dims) {
      v[out] = {y, true};
      return;
    }
    y = y.permute({0, 2, 3, 1});  // TFLite order, reduced axes of size 1
    for (auto it = axes.rbegin(); it != axes.rend(); ++it) y = y.squeeze(*it);
    v[out] = {y, false};
  };
}

Step Builder::Logistic() {
  ExpectArity(1, 1);
  const int x = In(0), out = Out();
  return [=](std::vector<Value>& v) { v[out] = {torch::sigmoid(v[x].t), v[x].nchw}; };
}

Step Builder::Prelu() {
  ExpectArity(2, 2);
  const int x = In(0), alpha = In(1), out = Out();
  // Fast path: a constant per-channel alpha ([C], [1, C], [1, 1, C] or [1, 1, 1, C]) on
  // a rank-4 input is LibTorch's prelu on NCHW with one weight per channel.
  std::optional<Tensor> per_channel;
  const auto& in = InShape(0);
  if (in.size() == 4 && p_.constants[alpha]) {
    const Tensor& a = *p_.constants[alpha];
    if (a.dim() >= 1 && a.dim() <= 4 && a.size(-1) == in[3] && a.numel() == in[3]) {
      per_channel = a.flatten().contiguous();
    }
  }
  if (per_channel) {
    const Tensor weight = *per_channel;
    return [=](std::vector<Value>& v) {
      v[out] = {torch::prelu(InNchw(v[x]), weight), true};
    };
  }
  return [=](std::vector<Value>& v) {
    const bool nchw = v[x].nchw || v[alpha].nchw;
    Tensor tx = nchw ? BroadcastToNchw(v[x]) : v[x].t;
    Tensor ta = nchw ? BroadcastToNchw(v[alpha]) : v[alpha].t;
    v[out] = {torch::where(tx >= 0, tx, tx * ta), nchw};
  };
}

Step Builder::Pad() {
  ExpectArity(2, 2);
  const size_t rank = InShape(0).size();
  const std::vector<int64_t> pads = ConstantInts(1);  // [rank, 2]: before, after
  if (pads.size() != 2 * rank || InShape(1).size() != 2) {
    Fail("paddings", "a " + std::to_string(rank) + "x2 tensor", ShapeString(InShape(1)));
  }
  for (int64_t p : pads) {
    if (p < 0) Fail("paddings", "non-negative values", std::to_string(p));
  }
  const auto& declared = g_.tensors[Out()].shape;
  for (size_t d = 0; d < rank; ++d) {
    if (declared.size() != rank ||
        InShape(0)[d] + pads[2 * d] + pads[2 * d + 1] != declared[d]) {
      Fail("paddings",
           "the padded input to match the output shape " + ShapeString(declared),
           "padding of " + ShapeString(InShape(0)) + " by " + ShapeString(InShape(1)));
    }
  }
  const int x = In(0), out = Out();
  return [=](std::vector<Value>& v) {
    const Value& in = v[x];
    // constant_pad_nd lists (before, after) from the last dimension back.
    std::vector<int64_t> torch_pads;
    for (int64_t d = static_cast<int64_t>(rank) - 1; d >= 0; --d) {
      int64_t tflite_dim = d;
      if (in.nchw) {
        static const int64_t kNchwToNhwc[] = {0, 3, 1, 2};
        tflite_dim = kNchwToNhwc[d];
      }
      torch_pads.push_back(pads[2 * tflite_dim]);
      torch_pads.push_back(pads[2 * tflite_dim + 1]);
    }
    v[out] = {torch::constant_pad_nd(in.t, torch_pads, 0.0), in.nchw};
  };
}

Step Builder::MaxPool() {
  ExpectArity(1, 1);
  ExpectRank(0, 4);
  ExpectActivation();
  const auto& o = op_->options;
  if (o.filter_h < 1 || o.filter_w < 1 || o.stride_h < 1 || o.stride_w < 1) {
    Fail("filter/stride", "positive values",
         std::to_string(o.filter_h) + "x" + std::to_string(o.filter_w) + " / " +
             std::to_string(o.stride_h) + "x" + std::to_string(o.stride_w));
  }
  const auto& in = InShape(0);
  SpatialPadding pad{PadAxis(in[1], o.filter_h, o.stride_h, 1, o.padding_valid),
                     PadAxis(in[2], o.filter_w, o.stride_w, 1, o.padding_valid)};
  const std::vector<int64_t> kernel{o.filter_h, o.filter_w},
      stride{o.stride_h, o.stride_w};
  const int x = In(0), out = Out(), activation = o.activation;
  const bool padded = pad.h.before + pad.h.after + pad.w.before + pad.w.after > 0;
  return [=](std::vector<Value>& v) {
    Tensor input = InNchw(v[x]);
    // TFLite's pools ignore the padded cells: pad with -inf.
    if (padded) input = PadSpatial(input, pad, -std::numeric_limits<double>::infinity());
    v[out] = {Activate(torch::max_pool2d(input, kernel, stride), activation), true};
  };
}

// TFLite's RESIZE_BILINEAR sampling of one axis (reference kernel): source coordinate
// y * scale, or (y + 0.5) * scale - 0.5 with half_pixel_centers; scale = in / out, or
// (in - 1) / (out - 1) with align_corners; neighbours floor and ceil clamped to the
// image, weight = coordinate - floor(coordinate). Computed in float as TFLite does.
struct ResizeAxis {
  Tensor lower, upper;  // int64 [out]
  Tensor weight;        // float [out]
};
ResizeAxis MakeResizeAxis(int64_t in, int64_t out, bool align_corners, bool half_pixel) {
  const float scale = (align_corners && out > 1) ? static_cast<float>(in - 1) / (out - 1)
                                                 : static_cast<float>(in) / out;
  ResizeAxis axis{torch::empty({out}, torch::kInt64), torch::empty({out}, torch::kInt64),
                  torch::empty({out}, torch::kFloat32)};
  for (int64_t i = 0; i < out; ++i) {
    const float source = half_pixel ? (static_cast<float>(i) + 0.5f) * scale - 0.5f
                                    : static_cast<float>(i) * scale;
    const float floor = std::floor(source);
    axis.lower[i] = std::max<int64_t>(static_cast<int64_t>(floor), 0);
    axis.upper[i] = std::min<int64_t>(static_cast<int64_t>(std::ceil(source)), in - 1);
    axis.weight[i] = source - floor;
  }
  return axis;
}

Step Builder::ResizeBilinear() {
  ExpectArity(2, 2);
  ExpectRank(0, 4);
  const std::vector<int64_t> size = ConstantInts(1);
  if (size.size() != 2 || size[0] < 1 || size[1] < 1) {
    Fail("size", "2 positive values (height, width)", ShapeString(InShape(1)));
  }
  const auto& declared = g_.tensors[Out()].shape;
  if (declared.size() != 4 || declared[1] != size[0] || declared[2] != size[1]) {
    Fail("size", "the output shape's height and width " + ShapeString(declared),
         std::to_string(size[0]) + "x" + std::to_string(size[1]));
  }
  const auto& o = op_->options;
  if (o.align_corners && o.half_pixel_centers) {
    Fail("options", "at most one of align_corners and half_pixel_centers", "both");
  }
  const auto& in = InShape(0);
  const ResizeAxis rows =
      MakeResizeAxis(in[1], size[0], o.align_corners, o.half_pixel_centers);
  const ResizeAxis cols =
      MakeResizeAxis(in[2], size[1], o.align_corners, o.half_pixel_centers);
  const int x = In(0), out = Out();
  return [=](std::vector<Value>& v) {
    Tensor t = InNchw(v[x]);
    const Tensor wy = rows.weight.view({1, 1, -1, 1});
    t = t.index_select(2, rows.lower) * (1 - wy) + t.index_select(2, rows.upper) * wy;
    const Tensor wx = cols.weight.view({1, 1, 1, -1});
    t = t.index_select(3, cols.lower) * (1 - wx) + t.index_select(3, cols.upper) * wx;
    v[out] = {t, true};
  };
}

Step Builder::Reshape() {
  ExpectArity(1, 2);
  // The file declares every tensor's static shape; the output's is the new shape.
  const auto& out_shape = g_.tensors[Out()].shape;
  if (g_.tensors[Out()].num_elements() != InTensor(0).num_elements()) {
    Fail("output shape", "as many elements as the input " + ShapeString(InShape(0)),
         ShapeString(out_shape));
  }
  const std::vector<int64_t> shape = ToInt64(out_shape);
  const int x = In(0), out = Out();
  return [=](std::vector<Value>& v) {
    v[out] = {InTfliteOrder(v[x]).reshape(shape), false};
  };
}

Step Builder::Concatenation() {
  ExpectActivation();
  if (op_->inputs.empty() || op_->outputs.size() != 1) {
    Fail("inputs/outputs", "at least 1 input and 1 output",
         std::to_string(op_->inputs.size()) + " inputs");
  }
  const int64_t rank = static_cast<int64_t>(InShape(0).size());
  int64_t axis = op_->options.axis;
  if (axis < -rank || axis >= rank) {
    Fail("axis",
         "a value in [-" + std::to_string(rank) + ", " + std::to_string(rank) + ")",
         std::to_string(axis));
  }
  if (axis < 0) axis += rank;
  std::vector<int> xs;
  for (size_t i = 0; i < op_->inputs.size(); ++i) xs.push_back(In(i));
  const int out = Out(), activation = op_->options.activation;
  return [=](std::vector<Value>& v) {
    bool all_nchw = rank == 4;
    for (int x : xs) all_nchw = all_nchw && v[x].nchw;
    std::vector<Tensor> parts;
    for (int x : xs) parts.push_back(all_nchw ? v[x].t : InTfliteOrder(v[x]));
    v[out] = {Activate(torch::cat(parts, all_nchw ? NchwDim(axis) : axis), activation),
              all_nchw};
  };
}

void Builder::BuildAll() {
  for (size_t i = 0; i < g_.ops.size(); ++i) {
    op_ = &g_.ops[i];
    op_index_ = static_cast<int>(i);
    if (op_->outputs.empty()) Fail("outputs", "at least one output", "none");
    std::optional<Step> step;
    switch (op_->code) {
      case kDequantize:
        Dequantize();
        break;
      case kConv2d:
        step = Conv(false);
        break;
      case kDepthwiseConv2d:
        step = Conv(true);
        break;
      case kFullyConnected:
        step = FullyConnected();
        break;
      case kAdd:
      case kSub:
      case kMul:
      case kDiv:
        step = Binary(op_->code);
        break;
      case kMean:
        step = Mean();
        break;
      case kLogistic:
        step = Logistic();
        break;
      case kPrelu:
        step = Prelu();
        break;
      case kPad:
        step = Pad();
        break;
      case kMaxPool2d:
        step = MaxPool();
        break;
      case kResizeBilinear:
        step = ResizeBilinear();
        break;
      case kReshape:
        step = Reshape();
        break;
      case kConcatenation:
        step = Concatenation();
        break;
      default:
        throw InputError(source_, "operator " + std::to_string(i),
                         std::string("a supported operator (") + kSupportedOps + ")",
                         op_->name);
    }
    if (step) {
      p_.steps.push_back(std::move(*step));
      p_.step_op.push_back(op_index_);
    }
  }
}

}  // namespace

void BuildSteps(const TfliteGraph& graph, const std::string& source, Program* program) {
  Builder(graph, source, program).BuildAll();
}

}  // namespace handlabel::tflite
