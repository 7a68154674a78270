#include "formats/pickle_value.h"

namespace handlabel {

const PickleValue* PickleValue::Find(const std::string& key) const {
  if (kind != Kind::kDict) return nullptr;
  for (const auto& [k, v] : entries) {
    if (k.kind == Kind::kText && k.text == key) return &v;
  }
  return nullptr;
}

std::string PickleValue::Describe() const {
  switch (kind) {
    case Kind::kNone:
      return "None";
    case Kind::kBool:
      return boolean ? "True" : "False";
    case Kind::kInt:
      return "int " + std::to_string(integer);
    case Kind::kFloat:
      return "float " + std::to_string(real);
    case Kind::kText:
      return "text '" + text.substr(0, 40) + "'";
    case Kind::kBytes:
      return "bytes of length " + std::to_string(text.size());
    case Kind::kList:
      return type_name + " of " + std::to_string(items.size()) + " items";
    case Kind::kDict:
      return type_name + " with " + std::to_string(entries.size()) + " entries";
    case Kind::kArray:
      return std::string(DTypeName(array->dtype)) + " array " + array->ShapeString() +
             (type_name == "numpy.ndarray" ? "" : " (" + type_name + ")");
    case Kind::kSparse:
      return sparse->format + "_matrix (" + std::to_string(sparse->rows) + ", " +
             std::to_string(sparse->cols) + ")";
    case Kind::kTensor:
      return "torch tensor";
    case Kind::kUnsupported:
      return "unsupported " + type_name + " (" + text + ")";
  }
  return "?";
}

}  // namespace handlabel
