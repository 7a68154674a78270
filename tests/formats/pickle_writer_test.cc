#include "formats/pickle_writer.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "formats/pickle_reader.h"

namespace handlabel {
namespace {

// Every dtype the dataset exports write, with bytes >= 0x80 (written as two UTF-8
// bytes of latin-1 text) and an empty array, read back by the restricted reader.
TEST(PickleWriter, ArraysReadBackExactly) {
  const std::vector<double> doubles = {-0.0, 1.5e-300, -2.25, 3e10};
  const std::vector<double> floats = {0.1, -1.0 / 3.0, 255.0, -1e-20, 7.0, 1e30};
  const std::vector<int64_t> ints = {-1, 0, 1 << 20, int64_t{1} << 40};
  NamedArrays arrays = {
      {"handPose", NdArray::FromDoublesAsFloat32({2, 3}, floats.data())},
      {"handTrans", NdArray::FromDoubles({4}, doubles.data())},
      {"ids", NdArray::FromInt64s({2, 2}, ints.data())},
      {"empty", NdArray::FromDoublesAsFloat32({0, 3, 4}, nullptr)},
      {"scalar", NdArray::FromDoubles({}, doubles.data() + 2)}};
  NdArray bytes;
  bytes.dtype = DType::kUInt8;
  bytes.itemsize = 1;
  bytes.shape = {256};
  for (int i = 0; i < 256; ++i) bytes.data.push_back(static_cast<uint8_t>(i));
  arrays.push_back({"seg", bytes});
  const PickleValue root = ReadPickle(PickleArrayDict(arrays), "written.pkl");
  ASSERT_EQ(root.kind, PickleValue::Kind::kDict);
  for (const auto& [name, array] : arrays) {
    const PickleValue* value = root.Find(name);
    ASSERT_NE(value, nullptr) << name;
    ASSERT_EQ(value->kind, PickleValue::Kind::kArray) << name;
    EXPECT_EQ(value->array->dtype, array.dtype) << name;
    EXPECT_EQ(value->array->shape, array.shape) << name;
    EXPECT_EQ(value->array->data, array.data) << name;  // bit for bit
  }
}

TEST(PickleWriter, RefusesTextArraysNamingThem) {
  const NamedArrays arrays = {{"objName", NdArray::FromText("mustard")}};
  try {
    PickleArrayDict(arrays);
    FAIL() << "a text array was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'objName'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace handlabel
