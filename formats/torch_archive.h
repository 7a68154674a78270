#pragma once
// Reads torch.save archives (the zip format PyTorch writes since 1.6) without
// LibTorch: "<name>/data.pkl" is a pickle whose tensors refer to storages stored as
// "<name>/data/<key>" entries (pickle_reader.h decodes it safely). Used to read
// checkpoints and state dicts as plain NdArrays.

#include <string>

#include "formats/npz.h"
#include "formats/pickle_value.h"
#include "formats/zip_reader.h"

namespace handlabel {

class TorchArchive {
 public:
  // Opens the zip and decodes data.pkl; throws InputError naming the file.
  explicit TorchArchive(const std::string& path);

  const PickleValue& root() const { return root_; }
  // A tensor's elements in C order, in its storage's dtype (checked against the
  // storage entry: offset + strides must stay inside it).
  NdArray Tensor(const TensorRef& tensor) const;
  // Every tensor in root() with its dotted path ("layer.weight"; nested dicts and lists
  // are joined with '.'), in pickle order. Non-tensor leaves are skipped.
  NamedArrays Tensors() const;

 private:
  ZipReader zip_;
  std::string prefix_;  // archive folder name, e.g. "archive/"
  PickleValue root_;
};

}  // namespace handlabel
