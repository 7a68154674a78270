#include "formats/torch_archive.h"

#include <cstring>

#include "core/errors.h"
#include "formats/pickle_reader.h"

namespace handlabel {
namespace {

void CollectTensors(const TorchArchive& archive, const PickleValue& v,
                    const std::string& name, int depth, NamedArrays* out) {
  if (depth > 64) return;  // the pickle reader already bounds nesting
  const auto join = [&](const std::string& key) {
    return name.empty() ? key : name + "." + key;
  };
  switch (v.kind) {
    case PickleValue::Kind::kTensor:
      out->emplace_back(name, archive.Tensor(*v.tensor));
      break;
    case PickleValue::Kind::kDict:
      for (const auto& [key, value] : v.entries) {
        const std::string k = key.kind == PickleValue::Kind::kText ? key.text
                              : key.kind == PickleValue::Kind::kInt
                                  ? std::to_string(key.integer)
                                  : "?";
        CollectTensors(archive, value, join(k), depth + 1, out);
      }
      break;
    case PickleValue::Kind::kList:
      for (size_t i = 0; i < v.items.size(); ++i) {
        CollectTensors(archive, v.items[i], join(std::to_string(i)), depth + 1, out);
      }
      break;
    default:
      break;
  }
}

}  // namespace

TorchArchive::TorchArchive(const std::string& path) : zip_(ZipReader::OpenFile(path)) {
  for (const ZipEntry& e : zip_.entries()) {
    const size_t slash = e.name.find('/');
    if (slash != std::string::npos &&
        e.name.compare(slash, std::string::npos, "/data.pkl") == 0) {
      prefix_ = e.name.substr(0, slash + 1);
      break;
    }
  }
  if (prefix_.empty()) {
    throw InputError(path, "data.pkl", "a torch.save archive with <name>/data.pkl",
                     "no such entry");
  }
  root_ = ReadPickle(zip_.Read(prefix_ + "data.pkl"), path + ":" + prefix_ + "data.pkl");
}

NdArray TorchArchive::Tensor(const TensorRef& t) const {
  const std::string entry = prefix_ + "data/" + t.storage_key;
  const std::string where = zip_.source() + ":" + entry;
  const int64_t item = FixedDTypeSize(t.dtype);
  const ZipEntry* e = zip_.Find(entry);
  if (!e) throw InputError(zip_.source(), entry, "the tensor's storage entry", "missing");
  // Compared by division: storage_numel * item may wrap around (2^62 + 24 floats
  // would pass as 96 bytes and the view check below would trust the huge count).
  if (t.storage_numel < 0 || e->uncompressed_size % item != 0 ||
      e->uncompressed_size / item != static_cast<uint64_t>(t.storage_numel)) {
    throw InputError(
        where, "storage",
        std::to_string(t.storage_numel) + " elements of " + DTypeName(t.dtype),
        std::to_string(e->uncompressed_size) + " bytes");
  }
  NdArray out;
  out.dtype = t.dtype;
  out.itemsize = item;
  out.shape = t.shape;
  // The last element reached must lie inside the storage.
  int64_t last = t.storage_offset;
  if (t.storage_offset < 0) throw InputError(where, "storage_offset", ">= 0");
  const int64_t n = CheckedByteCount(t.shape, item, kDefaultMaxArrayBytes, where) / item;
  for (size_t k = 0; k < t.shape.size(); ++k) {
    if (t.stride[k] < 0) throw InputError(where, "stride", "non-negative strides");
    if (t.shape[k] > 0 && t.stride[k] > 0) {
      if ((t.shape[k] - 1) > (t.storage_numel) / t.stride[k]) {
        throw InputError(where, "stride", "strides inside the storage", "too large");
      }
      last += (t.shape[k] - 1) * t.stride[k];
    }
  }
  if (n > 0 && last >= t.storage_numel) {
    throw InputError(
        where, "size",
        "a view inside the storage of " + std::to_string(t.storage_numel) + " elements",
        "element " + std::to_string(last));
  }
  const std::string storage = zip_.Read(*e);
  out.data.resize(static_cast<size_t>(n * item));
  std::vector<int64_t> index(t.shape.size(), 0);
  for (int64_t i = 0; i < n; ++i) {
    int64_t src = t.storage_offset;
    for (size_t k = 0; k < index.size(); ++k) src += index[k] * t.stride[k];
    std::memcpy(out.data.data() + i * item, storage.data() + src * item, item);
    for (size_t k = index.size(); k-- > 0;) {
      if (++index[k] < t.shape[k]) break;
      index[k] = 0;
    }
  }
  return out;
}

NamedArrays TorchArchive::Tensors() const {
  NamedArrays out;
  CollectTensors(*this, root_, "", 0, &out);
  return out;
}

}  // namespace handlabel
