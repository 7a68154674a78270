// Torch storages: persistent ids of torch.save archives, and storages saved inside a
// plain pickle (torch.storage._load_from_bytes), with every count checked against the
// bytes present before anything is allocated.
#include <cstring>

#include "formats/pickle_machine.h"
#include "formats/zip_reader.h"

namespace handlabel::pickle {

int PickleMachine::PersistentLoad(int pid) {
  // torch.save: ('storage', <Type>Storage, key, location, numel); the legacy
  // (pre-zip) format adds view_metadata, None for a whole storage.
  const std::vector<int>& t = TupleOf(pid, "persistent id");
  const bool legacy = t.size() == 6 && N(t[5]).kind == NodeKind::kNone;
  if ((t.size() != 5 && !legacy) || !IsText(t[0]) ||
      TextOf(t[0], "persistent id tag") != "storage" ||
      N(t[1]).kind != NodeKind::kGlobal || N(t[1]).global != Global::kStorage) {
    Fail(
        "a torch storage persistent id ('storage', torch.<Type>Storage, key, "
        "location, numel[, None])",
        "another persistent id");
  }
  auto ref = std::make_shared<TensorRef>();
  ref->dtype = N(t[1]).dtype;
  ref->storage_key = TextOf(t[2], "storage key");
  ref->device = TextOf(t[3], "storage location");
  ref->storage_numel = IntOf(t[4], "storage numel");
  if (ref->storage_numel < 0) Fail("a non-negative storage size", "a negative one");
  const int id = NewNode(NodeKind::kStorage);
  N(id).tensor = ref;
  return id;
}

// Pickling a tensor with plain pickle (not torch.save) stores its storage as
// _load_from_bytes(torch.save(storage)): the zip form or the legacy form. Only a single
// whole storage is accepted.
int PickleMachine::LoadStorageFromBytes(const std::string& saved) {
  const std::string what = source_ + " (saved torch storage)";
  std::string data;
  const Node storage = LooksLikeZip(saved) ? ReadZipStorage(saved, what, &data)
                                           : ReadLegacyStorage(saved, what, &data);
  const int64_t itemsize = FixedDTypeSize(storage.tensor->dtype);
  const int64_t numel = storage.tensor->storage_numel;
  if (numel > limits_.max_total_bytes / itemsize ||
      static_cast<int64_t>(data.size()) != numel * itemsize) {
    Fail(std::to_string(numel) + " elements of " + std::to_string(itemsize) +
             " bytes in the saved storage",
         std::to_string(data.size()) + " bytes");
  }
  ChargeBytes(data.size());
  auto array = std::make_shared<NdArray>();
  array->dtype = storage.tensor->dtype;
  array->itemsize = itemsize;
  array->shape = {numel};
  array->data.assign(data.begin(), data.end());
  const int id = NewNode(NodeKind::kStorage);
  N(id).tensor = storage.tensor;
  N(id).array = array;
  return id;
}

// The zip form: <name>/data.pkl + <name>/data/<key>.
Node PickleMachine::ReadZipStorage(const std::string& saved, const std::string& what,
                                   std::string* data) {
  const ZipReader zip = ZipReader::FromBytes(saved, what);
  const ZipEntry* pkl = nullptr;
  for (const ZipEntry& e : zip.entries()) {
    const size_t n = e.name.size();
    if (n >= 8 && e.name.compare(n - 8, 8, "data.pkl") == 0 &&
        (n == 8 || e.name[n - 9] == '/'))
      pkl = &e;
  }
  if (!pkl) Fail("a torch.save archive with data.pkl", "none in the saved storage");
  const std::string pickled = zip.Read(*pkl);
  const Node storage = PickleMachine(pickled, what, limits_).RunToNode();
  RequireSavedStorage(storage);
  const std::string prefix = pkl->name.substr(0, pkl->name.size() - 8);
  const std::string entry = prefix + "data/" + storage.tensor->storage_key;
  if (!zip.Find(entry)) Fail("the storage entry " + entry, "none");
  *data = zip.Read(entry);
  return storage;
}

// The legacy form: magic number, protocol 1001, sys_info, the storage's persistent id,
// its key list, then an int64 element count and the raw little-endian elements.
Node PickleMachine::ReadLegacyStorage(const std::string& saved, const std::string& what,
                                      std::string* data) {
  PickleMachine version(saved, what, limits_, SkipTorchMagic(saved));
  const PickleValue protocol = version.Run();
  if (protocol.kind != PickleValue::Kind::kInt || protocol.integer != 1001) {
    Fail("torch legacy protocol version 1001", protocol.Describe());
  }
  PickleMachine sys_info(saved, what, limits_, version.end());
  const PickleValue info = sys_info.Run();
  const PickleValue* little = info.Find("little_endian");
  if (little && little->kind == PickleValue::Kind::kBool && !little->boolean) {
    Fail("a storage saved on a little-endian machine", "big-endian");
  }
  PickleMachine main(saved, what, limits_, sys_info.end());
  const Node storage = main.RunToNode();
  RequireSavedStorage(storage);
  PickleMachine keys(saved, what, limits_, main.end());
  const PickleValue key_list = keys.Run();
  if (key_list.kind != PickleValue::Kind::kList || key_list.items.size() != 1 ||
      key_list.items[0].kind != PickleValue::Kind::kText ||
      key_list.items[0].text != storage.tensor->storage_key) {
    Fail("the key list ['" + storage.tensor->storage_key + "']", key_list.Describe());
  }
  size_t pos = keys.end();
  if (saved.size() - pos < 8) Fail("the storage's element count", "end of data");
  int64_t count = 0;
  for (int k = 7; k >= 0; --k)
    count = (count << 8) | static_cast<uint8_t>(saved[pos + k]);
  pos += 8;
  if (count != storage.tensor->storage_numel) {
    Fail(std::to_string(storage.tensor->storage_numel) + " stored elements",
         std::to_string(count));
  }
  *data = saved.substr(pos);
  return storage;
}

// The legacy format's first pickle: the magic number 0x1950a86a20f9469cfc6c (a
// 10-byte LONG1). Returns the offset after it.
size_t PickleMachine::SkipTorchMagic(const std::string& saved) {
  static const unsigned char kMagic[] = {0x8a, 0x0a, 0x6c, 0xfc, 0x9c, 0x46, 0xf9,
                                         0x20, 0x6a, 0xa8, 0x50, 0x19, '.'};
  size_t pos = 0;
  if (saved.size() >= 2 && static_cast<uint8_t>(saved[0]) == 0x80) pos = 2;  // PROTO
  if (saved.size() < pos + sizeof(kMagic) ||
      std::memcmp(saved.data() + pos, kMagic, sizeof(kMagic)) != 0) {
    Fail("torch.save bytes (zip, or the legacy magic number)", "other bytes");
  }
  return pos + sizeof(kMagic);
}

void PickleMachine::RequireSavedStorage(const Node& storage) {
  if (storage.kind != NodeKind::kStorage || !storage.tensor) {
    Fail("a saved torch storage", DescribeNode(storage));
  }
}

// The elements of a tensor view of an in-memory storage, in C order. Offsets and
// strides are checked against the storage before anything is read.
std::shared_ptr<NdArray> PickleMachine::TensorFromStorage(const TensorRef& t,
                                                          const NdArray& storage) {
  const int64_t stored = storage.shape[0];
  int64_t numel = 1, last = t.storage_offset;
  for (size_t d = 0; d < t.shape.size(); ++d) {
    if (t.shape[d] < 0 || t.stride[d] < 0) {
      Fail("non-negative tensor sizes and strides", "a negative one");
    }
    if (t.shape[d] == 0) {
      numel = 0;
      continue;
    }
    if (t.stride[d] > 0 && t.shape[d] - 1 > stored / t.stride[d]) {
      Fail("a tensor view inside its storage", "strides beyond it");
    }
    last += (t.shape[d] - 1) * t.stride[d];  // each term <= stored: no overflow
    if (numel > 0 && t.shape[d] > limits_.max_total_bytes / numel) {
      Fail("a tensor within the size limit", "a larger one");
    }
    numel *= t.shape[d];
  }
  if (numel > 0 &&
      (t.storage_offset < 0 || t.storage_offset > stored || last >= stored)) {
    Fail("a tensor view inside its storage of " + std::to_string(stored) + " elements",
         "element " + std::to_string(last));
  }
  auto a = std::make_shared<NdArray>();
  a->dtype = storage.dtype;
  a->itemsize = storage.itemsize;
  a->shape = t.shape;
  ChargeBytes(static_cast<uint64_t>(numel * a->itemsize));
  a->data.resize(static_cast<size_t>(numel * a->itemsize));
  std::vector<int64_t> index(t.shape.size(), 0);
  for (int64_t i = 0; i < numel; ++i) {
    int64_t at = t.storage_offset;
    for (size_t d = 0; d < index.size(); ++d) at += index[d] * t.stride[d];
    std::memcpy(a->data.data() + i * a->itemsize, storage.data.data() + at * a->itemsize,
                static_cast<size_t>(a->itemsize));
    for (size_t d = index.size(); d-- > 0;) {  // next index in C order
      if (++index[d] < t.shape[d]) break;
      index[d] = 0;
    }
  }
  return a;
}

}  // namespace handlabel::pickle
