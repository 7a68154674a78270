#include "network/poem/tensor_shape.h"

#include "core/text.h"

namespace handlabel {

std::string ShapeString(const std::vector<int64_t>& sizes) {
  std::vector<std::string> items;
  for (const int64_t size : sizes) items.push_back(std::to_string(size));
  return "(" + Join(items) + ")";
}

std::string ShapeString(const torch::Tensor& t) {
  return t.defined() ? ShapeString(t.sizes().vec()) : "undefined";
}

}  // namespace handlabel
