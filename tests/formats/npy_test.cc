#include "formats/npy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string Fixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/npy/" + name;
}

// The logical values make_npy_fixtures.py stores for element i of each kind.
double Expected(DType dtype, int i) {
  switch (dtype) {
    case DType::kBool:
      return i % 3 == 0;
    case DType::kUInt8:
    case DType::kUInt32:
      return i * 3;
    case DType::kInt16:
    case DType::kInt32:
    case DType::kInt64:
      return i * 5 - 40;
    default:
      return i * 1.25 - 7.0;
  }
}

struct NumpyCase {
  const char* file;
  DType dtype;
};

class NumpyWritten : public ::testing::TestWithParam<NumpyCase> {};

TEST_P(NumpyWritten, ReadsLogicalValuesInCOrder) {
  const NdArray a = ReadNpyFile(Fixture(GetParam().file));
  EXPECT_EQ(a.dtype, GetParam().dtype);
  EXPECT_EQ(a.shape, (std::vector<int64_t>{2, 3, 4}));
  const std::vector<double> v = a.ToDoubles();
  ASSERT_EQ(v.size(), 24u);
  for (int i = 0; i < 24; ++i) EXPECT_EQ(v[i], Expected(a.dtype, i)) << "element " << i;
}

INSTANTIATE_TEST_SUITE_P(Files, NumpyWritten,
                         ::testing::Values(NumpyCase{"f8_c.npy", DType::kFloat64},
                                           NumpyCase{"f4_big.npy", DType::kFloat32},
                                           NumpyCase{"f2_little.npy", DType::kFloat16},
                                           NumpyCase{"i2_fortran.npy", DType::kInt16},
                                           NumpyCase{"i8_big_fortran.npy", DType::kInt64},
                                           NumpyCase{"u1.npy", DType::kUInt8},
                                           NumpyCase{"u4_big.npy", DType::kUInt32},
                                           NumpyCase{"b1.npy", DType::kBool},
                                           NumpyCase{"i4_v2.npy", DType::kInt32},
                                           NumpyCase{"f8_v3.npy", DType::kFloat64}));

TEST(Npy, ReadsUnicodeScalarAndEmptyArrays) {
  EXPECT_EQ(ReadNpyFile(Fixture("unicode.npy")).ToText(), "right");
  const NdArray s = ReadNpyFile(Fixture("scalar.npy"));
  EXPECT_EQ(s.ndim(), 0);
  EXPECT_EQ(s.ToDoubles(), std::vector<double>{2.5});
  const NdArray e = ReadNpyFile(Fixture("empty.npy"));
  EXPECT_EQ(e.shape, (std::vector<int64_t>{0, 3}));
  EXPECT_TRUE(e.data.empty());
}

TEST(Npy, OurBytesEqualNumpysForTheSameArray) {
  // numpy writes version 1.0, '<f8', C order, header padded to 64 bytes: ours must be
  // byte-identical, which is the strongest check that numpy reads what we write.
  const NdArray a = ReadNpyFile(Fixture("f8_c.npy"));
  EXPECT_EQ(SerializeNpy(a), testing::ReadFileBytes(Fixture("f8_c.npy")));
  EXPECT_EQ(SerializeNpy(ReadNpyFile(Fixture("u1.npy"))),
            testing::ReadFileBytes(Fixture("u1.npy")));
  EXPECT_EQ(SerializeNpy(ReadNpyFile(Fixture("unicode.npy"))),
            testing::ReadFileBytes(Fixture("unicode.npy")));
  EXPECT_EQ(SerializeNpy(ReadNpyFile(Fixture("scalar.npy"))),
            testing::ReadFileBytes(Fixture("scalar.npy")));
}

TEST(Npy, TextArraysAreNumpysFixedWidthUnicode) {
  // numpy's np.array(["f1", "frame_10", "\u00e9"]) is '<U8': 8 UCS-4 code points per
  // element, NUL padded; the 0-d form is what FromText always wrote.
  const NdArray a = NdArray::FromTexts({"f1", "frame_10", "\xc3\xa9"});
  EXPECT_EQ(a.dtype, DType::kUnicode);
  EXPECT_EQ(a.shape, (std::vector<int64_t>{3}));
  EXPECT_EQ(a.itemsize, 32);
  EXPECT_EQ(DTypeDescr(a), "<U8");
  uint32_t third;
  std::memcpy(&third, a.data.data() + 2 * 32, 4);
  EXPECT_EQ(third, 0xE9u);
  const NdArray none = NdArray::FromTexts({});
  EXPECT_EQ(none.shape, (std::vector<int64_t>{0}));
  EXPECT_EQ(DTypeDescr(none), "<U1");
  EXPECT_EQ(SerializeNpy(NdArray::FromText("right")),
            testing::ReadFileBytes(Fixture("unicode.npy")));
}

TEST(Npy, RoundTripsEveryDTypeThroughAFile) {
  const std::string dir = testing::ScratchDir();
  for (DType t :
       {DType::kBool, DType::kInt8, DType::kUInt8, DType::kInt16, DType::kUInt16,
        DType::kInt32, DType::kUInt32, DType::kInt64, DType::kUInt64}) {
    std::vector<int64_t> v(15);
    for (auto& x : v) x = static_cast<int64_t>(testing::Uniform(0, 100));
    const NdArray a = NdArray::FromInt64s({3, 5}, v.data(), t);
    WriteNpyFile(dir + "/a.npy", a);
    const NdArray b = ReadNpyFile(dir + "/a.npy");
    EXPECT_EQ(b.dtype, t);
    EXPECT_EQ(b.shape, a.shape);
    EXPECT_EQ(b.data, a.data) << DTypeName(t);
  }
  std::vector<double> d(7);
  for (auto& x : d) x = testing::Gaussian(1e3);
  const NdArray a = NdArray::FromDoubles({7}, d.data());
  WriteNpyFile(dir + "/d.npy", a);
  EXPECT_EQ(ReadNpyFile(dir + "/d.npy").ToDoubles(), d);
}

TEST(Npy, HalfPrecisionDecodesExactly) {
  EXPECT_EQ(HalfToDouble(0x3C00), 1.0);
  EXPECT_EQ(HalfToDouble(0xC000), -2.0);
  EXPECT_EQ(HalfToDouble(0x7BFF), 65504.0);
  EXPECT_EQ(HalfToDouble(0x0001), std::ldexp(1.0, -24));
  EXPECT_TRUE(std::isinf(HalfToDouble(0x7C00)));
  EXPECT_TRUE(std::isnan(HalfToDouble(0x7E00)));
}

std::string ErrorOf(const std::string& bytes) {
  try {
    ParseNpy(bytes, "bad.npy");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Npy, RejectsTruncatedAndHostileFilesWithClearErrors) {
  const std::string good = testing::ReadFileBytes(Fixture("f8_c.npy"));
  EXPECT_NE(ErrorOf(good.substr(0, good.size() - 8)).find("truncated"),
            std::string::npos);
  EXPECT_NE(ErrorOf(good.substr(0, 40)).find("truncated"), std::string::npos);
  EXPECT_NE(ErrorOf("hello").find("magic"), std::string::npos);
  std::string huge = good;
  const size_t shape = huge.find("(2, 3, 4)");
  huge.replace(shape, 9, "(99999999999, 99999999)");
  EXPECT_NE(ErrorOf(huge).find("limit"), std::string::npos) << ErrorOf(huge);
  std::string structured = good;
  structured.replace(structured.find("'<f8'"), 5, "[('a','<f8')]");
  EXPECT_NE(ErrorOf(structured).find("descr"), std::string::npos);
  std::string object = good;
  object.replace(object.find("'<f8'"), 5, "'|O' ");
  EXPECT_NE(ErrorOf(object).find("object array"), std::string::npos);
  std::string version = good;
  version[6] = 9;
  EXPECT_NE(ErrorOf(version).find("version"), std::string::npos);
}

}  // namespace
}  // namespace handlabel
