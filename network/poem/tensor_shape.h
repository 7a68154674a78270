#pragma once
// Tensor shapes as message text, "(2, 3)". Internal to network/poem/ (includes LibTorch).

#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

// "(a, b, ...)", "(n)" for one dimension, "()" for none.
std::string ShapeString(const std::vector<int64_t>& sizes);

// The tensor's sizes as above; "undefined" for an undefined tensor (a missing input),
// which has no sizes to print.
std::string ShapeString(const torch::Tensor& t);

}  // namespace handlabel
