#include "formats/pickle_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "formats/pickle_globals.h"
#include "formats/torch_archive.h"
#include "formats/zip_reader.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using K = PickleValue::Kind;
using namespace std::string_literals;

std::string DataPath(const std::string& rel) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/" + rel;
}

// The error message ReadPickle gives, or "" when it succeeds.
std::string PickleError(const std::string& bytes, const PickleLimits& limits = {}) {
  try {
    ReadPickle(bytes, "hostile.pkl", limits);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class SmallPickle : public ::testing::TestWithParam<int> {};

// make_mano_fixtures.py pickles one dict at every protocol: the text opcodes of
// protocol 0, the binary ones of 1-3, frames / memoize / short unicode of 4 and the
// bytearray buffers of 5 must all give the same values.
TEST_P(SmallPickle, EveryProtocolDecodesTheSameValues) {
  const PickleValue v =
      ReadPickleFile(DataPath("mano/small_p" + std::to_string(GetParam()) + ".pkl"));
  ASSERT_EQ(v.kind, K::kDict);
  const PickleValue* arr = v.Find("arr");
  ASSERT_NE(arr, nullptr);
  ASSERT_EQ(arr->kind, K::kArray);
  EXPECT_EQ(arr->array->shape, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(arr->array->ToDoubles(), (std::vector<double>{0, 1.5, 3, 4.5, 6, 7.5}));
  EXPECT_EQ(v.Find("big")->array->ToInt64s(), (std::vector<int64_t>{1, -2, 3}));
  EXPECT_EQ(v.Find("fortran")->array->ToInt64s(),
            (std::vector<int64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(v.Find("text")->text, "h\xc3\xa9llo \xe2\x98\x83");
  EXPECT_EQ(v.Find("bytes")->kind, K::kBytes);
  EXPECT_EQ(v.Find("bytes")->text, std::string("\x00\xff\n", 3));
  const std::vector<int64_t> ints = {
      0,         1,        -1, 255, 256, 65536, -(int64_t{1} << 31), int64_t{1} << 40,
      INT64_MIN, INT64_MAX};
  const PickleValue* tuple = v.Find("ints");
  ASSERT_EQ(tuple->items.size(), ints.size());
  for (size_t i = 0; i < ints.size(); ++i) EXPECT_EQ(tuple->items[i].integer, ints[i]);
  EXPECT_EQ(v.Find("float")->real, 0.1);
  EXPECT_EQ(v.Find("none")->kind, K::kNone);
  EXPECT_TRUE(v.Find("flags")->items[0].boolean);
  EXPECT_FALSE(v.Find("flags")->items[1].boolean);
  EXPECT_EQ(v.Find("set")->items.at(0).integer, 3);
  EXPECT_EQ(v.Find("od")->Find("k")->integer, 1);
  EXPECT_EQ(v.Find("scalar")->real, 2.5);
  EXPECT_EQ(v.Find("nested")->items.at(0).items.at(1).items.at(0).integer, 2);
}

INSTANTIATE_TEST_SUITE_P(Protocols, SmallPickle, ::testing::Range(0, 6));

// The name (or none) of every byte value as an opcode, against
// tests/data/reference/pickle_opcode_names.txt (strings only: exact).
TEST(PickleOpcodeName, EveryByteKeepsItsName) {
  testing::ReferenceValues values("pickle_opcode_names");
  int named = 0;
  for (int op = 0; op < 256; ++op) {
    const char* name = pickle::PickleOpcodeName(static_cast<uint8_t>(op));
    values.Exact("opcode" + std::to_string(op), name ? name : "(none)");
    named += name != nullptr;
  }
  EXPECT_EQ(named, 68);
  EXPECT_STREQ(pickle::PickleOpcodeName('('), "MARK");
  EXPECT_STREQ(pickle::PickleOpcodeName(0x98), "READONLY_BUFFER");
  EXPECT_EQ(pickle::PickleOpcodeName(0x99), nullptr);
  EXPECT_TRUE(values.Compare(0, 0));
}

TEST(PickleReader, ReadsTheOfficialMANOStructure) {
  const PickleValue v = ReadPickleFile(DataPath("mano/mano_py2_right.pkl"));
  EXPECT_EQ(v.Find("bs_style")->text, "lbs");
  const PickleValue* shapedirs = v.Find("shapedirs");
  EXPECT_EQ(shapedirs->type_name, "chumpy.reordering.Select");
  EXPECT_EQ(shapedirs->array->shape, (std::vector<int64_t>{12, 3, 10}));
  EXPECT_EQ(v.Find("weights")->type_name, "chumpy.ch.Ch");
  const PickleValue* reg = v.Find("J_regressor");
  ASSERT_EQ(reg->kind, K::kSparse);
  EXPECT_EQ(reg->sparse->format, "csc");
  EXPECT_EQ(reg->sparse->rows, 16);
  EXPECT_EQ(reg->sparse->cols, 12);
  EXPECT_EQ(v.Find("f")->array->dtype, DType::kUInt32);
}

TEST(PickleReader, ReadsTorchSaveStateDicts) {
  const TorchArchive archive(DataPath("npy/state_dict.pt"));
  const NamedArrays tensors = archive.Tensors();
  ASSERT_EQ(tensors.size(), 4u);
  EXPECT_EQ(tensors[0].first, "weight");
  EXPECT_EQ(tensors[0].second.dtype, DType::kFloat32);
  EXPECT_EQ(tensors[0].second.shape, (std::vector<int64_t>{2, 3, 4}));
  for (int i = 0; i < 24; ++i) EXPECT_EQ(tensors[0].second.ToDoubles()[i], i * 1.25 - 7);
  EXPECT_EQ(tensors[1].second.ToDoubles(), (std::vector<double>{-7, -5.75, -4.5, -3.25}));
  // steps = arange(24).reshape(6, 4).T[1:] * 5 - 40: a strided view at offset 1.
  const NdArray& steps = tensors[2].second;
  EXPECT_EQ(steps.shape, (std::vector<int64_t>{3, 6}));
  const std::vector<int64_t> s = steps.ToInt64s();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 6; ++c) EXPECT_EQ(s[r * 6 + c], (c * 4 + r + 1) * 5 - 40);
  }
  EXPECT_EQ(tensors[3].second.dtype, DType::kFloat16);
  EXPECT_EQ(tensors[3].second.ToDoubles()[5], 5 * 1.25 - 7);
}

// ---- hostile input -----------------------------------------------------------------

TEST(PickleReader, RefusesUnknownGlobalsNamingThemAndTheOffset) {
  // cos\nsystem\n(S'echo hacked'\ntR.  -- the classic.
  const std::string evil = "cos\nsystem\n(S'echo hacked'\ntR.";
  const std::string error = PickleError(evil);
  EXPECT_NE(error.find("global 'os.system'"), std::string::npos) << error;
  EXPECT_NE(error.find("GLOBAL at offset 0"), std::string::npos) << error;
  EXPECT_NE(error.find("hostile.pkl"), std::string::npos) << error;
  // Protocol 4 STACK_GLOBAL of builtins.eval.
  const std::string eval =
      "\x80\x04\x8c\x08"
      "builtins"
      "\x8c\x04"
      "eval"
      "\x93"
      "\x8c\x01"
      "1"
      "\x85R.";
  EXPECT_NE(PickleError(eval).find("global 'builtins.eval'"), std::string::npos);
  // A known class is not a licence to call anything: REDUCE on numpy.ndarray.
  EXPECT_NE(PickleError("cnumpy\nndarray\n)R.").find("REDUCE"), std::string::npos);
  // Persistent ids other than torch storages, extension codes, out-of-band buffers.
  EXPECT_NE(PickleError("Pfoo\n.").find("PERSID"), std::string::npos);
  EXPECT_NE(PickleError("\x80\x02\x82\x01.").find("EXT1"), std::string::npos);
  EXPECT_NE(PickleError("\x80\x05\x97.").find("NEXT_BUFFER"), std::string::npos);
  EXPECT_NE(PickleError("\xff").find("unknown opcode"), std::string::npos);
}

TEST(PickleReader, RefusesHugeDeclaredSizesBeforeAllocating) {
  // BINBYTES8 declaring 2^62 bytes, BINUNICODE8 the same, LONG4 with a 2 GiB integer.
  EXPECT_NE(PickleError(std::string("\x80\x04\x8e\x00\x00\x00\x00\x00\x00\x00\x40", 11))
                .find("truncated"),
            std::string::npos);
  EXPECT_NE(PickleError(std::string("\x80\x04\x8d\xff\xff\xff\xff\xff\xff\xff\x7f", 11))
                .find("truncated"),
            std::string::npos);
  EXPECT_NE(
      PickleError(std::string("\x80\x02\x8b\x00\x00\x00\x80", 7)).find("at most 8 bytes"),
      std::string::npos);
  // An ndarray whose shape claims 10^18 elements but carries 8 bytes of data.
  std::string bytes = testing::ReadFileBytes(DataPath("mano/small_p2.pkl"));
  const std::string shape = std::string("K\x02K\x03\x86", 5);  // (2, 3)
  const size_t at = bytes.find(shape);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, shape.size(),
                std::string("\x8a\x08\x00\x00\x64\xa7\xb3\xb6\xe0\x0dK\x03\x86", 13));
  const std::string error = PickleError(bytes);
  EXPECT_NE(error.find("limit"), std::string::npos) << error;
  // A memo PUT at index 2^32-1 does not allocate 2^32 slots.
  EXPECT_EQ(
      PickleError(std::string("\x80\x02N\x72\xff\xff\xff\xff\x6a\xff\xff\xff\xff.", 14)),
      "");
  // Value and byte budgets.
  PickleLimits tight;
  tight.max_values = 100;
  std::string many = "\x80\x02]";
  for (int i = 0; i < 200; ++i) many += "Na";
  EXPECT_NE(PickleError(many + ".", tight).find("at most 100 values"), std::string::npos);
  tight = PickleLimits();
  tight.max_total_bytes = 1000;
  EXPECT_NE(
      PickleError(testing::ReadFileBytes(DataPath("mano/mano_py2_right.pkl")), tight)
          .find("at most 1000 bytes"),
      std::string::npos);
}

TEST(PickleReader, RefusesDeepNestingAndCyclesWithoutRecursingDeeply) {
  // 100000 nested lists: ]]]]...a a a  (each APPEND puts the inner list into the outer).
  std::string deep = "\x80\x02";
  for (int i = 0; i < 100000; ++i) deep += "]";
  for (int i = 0; i < 99999; ++i) deep += "a";
  deep += ".";
  EXPECT_NE(PickleError(deep).find("levels deep"), std::string::npos);
  // A list that contains itself: ] q0 h0 a .
  const std::string cycle =
      "\x80\x02]q\x00h\x00"
      "a."s;
  EXPECT_NE(PickleError(cycle).find("levels deep"), std::string::npos)
      << PickleError(cycle);
  // Exponential sharing: L0=[], L(k+1)=[Lk, Lk]: 2^40 leaves if expanded.
  std::string laughs = "\x80\x02]q\x00"s;
  for (int k = 0; k < 40; ++k) {
    laughs += "](h";
    laughs += static_cast<char>(k);
    laughs += "h";
    laughs += static_cast<char>(k);
    laughs += "eq";
    laughs += static_cast<char>(k + 1);
  }
  laughs += ".";
  PickleLimits limits;
  limits.max_values = 100000;
  EXPECT_NE(PickleError(laughs, limits).find("values"), std::string::npos);
}

TEST(PickleReader, EveryTruncationFailsCleanly) {
  for (const char* file : {"mano/small_p0.pkl", "mano/small_p2.pkl", "mano/small_p5.pkl",
                           "mano/mano_py2_right.pkl"}) {
    const std::string bytes = testing::ReadFileBytes(DataPath(file));
    const size_t step = std::max<size_t>(1, bytes.size() / 300);
    for (size_t n = 0; n + 1 < bytes.size(); n += step) {
      const std::string error = PickleError(bytes.substr(0, n));
      EXPECT_NE(error, "") << file << " cut at " << n;
    }
  }
}

TEST(PickleReader, RandomByteFlipsNeverCrash) {
  const std::string good = testing::ReadFileBytes(DataPath("mano/mano_py2_right.pkl"));
  for (int trial = 0; trial < 300; ++trial) {
    std::string bad = good;
    for (int k = 0; k < 3; ++k) {
      bad[static_cast<size_t>(testing::Uniform(0, bad.size() - 1))] =
          static_cast<char>(testing::Uniform(0, 256));
    }
    PickleError(bad);  // either decodes or throws InputError; never anything else
  }
}

// The fuzz target's corpus (fuzz/corpus/pickle_reader: named seeds plus inputs the
// fuzzer kept), each input whole and with random edits; runs without clang.
TEST(PickleReader, FuzzCorpusSmoke) {
  const std::string dir =
      std::string(HANDLABEL_SOURCE_DIR) + "/fuzz/corpus/pickle_reader";
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string bytes = testing::ReadFileBytes(entry.path().string());
    const std::string error = PickleError(bytes);
    if (entry.path().extension() == ".pkl") {
      EXPECT_EQ(error, "") << entry.path();
    }
    ++inputs;
    for (int trial = 0; trial < 20 && !bytes.empty(); ++trial) {
      std::string bad = bytes;
      const int edits = 1 + static_cast<int>(testing::Uniform(0, 4));
      for (int k = 0; k < edits && !bad.empty(); ++k) {
        const size_t at = static_cast<size_t>(testing::Uniform(0, bad.size() - 1));
        switch (static_cast<int>(testing::Uniform(0, 3))) {
          case 0:
            bad[at] = static_cast<char>(testing::Uniform(0, 256));
            break;
          case 1:
            bad.erase(at, 1);
            break;
          default:
            bad.insert(at, 1, static_cast<char>(testing::Uniform(0, 256)));
        }
      }
      PickleError(bad);  // decodes or throws InputError, nothing else
    }
  }
  EXPECT_GE(inputs, 10);
}

// Python 2 protocol 0 (text) forms that Python 3 never writes: STRING with repr
// escapes, INT booleans, LONG with the L suffix, FLOAT, UNICODE raw escapes.
TEST(PickleReader, ReadsPython2TextProtocol) {
  const std::string p0 =
      "(dp0\nS'str'\np1\nS'a\\x00b\\n\\'c\\\\'\np2\nsS'flag'\np3\nI01\nsS'long'\np4\n"
      "L12345678901L\nsS'float'\np5\nF0.25\nsS'uni'\np6\nVh\\u00e9\\u2603\np7\ns"
      "S'list'\np8\n(lp9\nI1\naI-2\nag1\nas.";
  const PickleValue v = ReadPickle(p0, "p0.pkl");
  ASSERT_EQ(v.kind, K::kDict) << v.Describe();
  EXPECT_EQ(v.Find("str")->text, std::string("a\0b\n'c\\", 7));
  EXPECT_TRUE(v.Find("flag")->boolean);
  EXPECT_EQ(v.Find("long")->integer, 12345678901);
  EXPECT_EQ(v.Find("float")->real, 0.25);
  EXPECT_EQ(v.Find("uni")->text, "h\xc3\xa9\xe2\x98\x83");
  const PickleValue* list = v.Find("list");
  ASSERT_EQ(list->items.size(), 3u);
  EXPECT_EQ(list->items[1].integer, -2);
  EXPECT_EQ(list->items[2].text, "str");  // GET of the memoised key
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// ---- tensors pickled with plain pickle (torch.storage._load_from_bytes) ------------

// The dict of tests/data/datasets/make_tensor_pickles.py, whichever form it was
// written in: every tensor becomes a plain array with torch's values.
void ExpectTensorValues(const PickleValue& v) {
  ASSERT_EQ(v.kind, K::kDict) << v.Describe();
  const PickleValue* f32 = v.Find("f32");
  ASSERT_EQ(f32->kind, K::kArray) << f32->Describe();
  EXPECT_EQ(f32->array->dtype, DType::kFloat32);
  EXPECT_EQ(f32->array->shape, (std::vector<int64_t>{3, 3}));
  for (int i = 0; i < 9; ++i) EXPECT_EQ(f32->array->ToDoubles()[i], i / 8.0);
  // base = arange(24).reshape(4, 6) * 0.25 - 2; its transpose (strides 1, 6) and
  // base[1:, 2:4] (offset 8): C order as numpy would give them.
  const auto base = [](int r, int c) { return (r * 6 + c) * 0.25 - 2; };
  const NdArray& t = *v.Find("f64_transposed")->array;
  EXPECT_EQ(t.shape, (std::vector<int64_t>{6, 4}));
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ(t.ToDoubles()[r * 4 + c], base(c, r));
  }
  const NdArray& o = *v.Find("f64_offset")->array;
  EXPECT_EQ(o.shape, (std::vector<int64_t>{3, 2}));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 2; ++c) EXPECT_EQ(o.ToDoubles()[r * 2 + c], base(r + 1, c + 2));
  }
  EXPECT_EQ(v.Find("i64")->array->ToInt64s(),
            (std::vector<int64_t>{-3, 0, 7, int64_t{1} << 40}));
  EXPECT_EQ(v.Find("f16")->array->dtype, DType::kFloat16);
  EXPECT_EQ(v.Find("f16")->array->ToDoubles(), (std::vector<double>{0.5, -1.25, 3.0}));
  EXPECT_EQ(v.Find("u8")->array->ToInt64s(), (std::vector<int64_t>{0, 255, 7, 9}));
  EXPECT_EQ(v.Find("scalar")->array->shape, std::vector<int64_t>{});
  EXPECT_EQ(v.Find("scalar")->array->ToDoubles(), std::vector<double>{2.5});
  const PickleValue* list = v.Find("nested")->Find("list");
  ASSERT_EQ(list->items.size(), 1u);
  EXPECT_EQ(list->items[0].array->ToDoubles(), (std::vector<double>{1, 1}));
}

TEST(PickleReader, DecodesTensorsPickledWithPlainPickle) {
  for (const char* name :
       {"tensors_legacy_p2.pkl", "tensors_legacy_p4.pkl", "tensors_zip.pkl"}) {
    SCOPED_TRACE(name);
    ExpectTensorValues(ReadPickleFile(DataPath(std::string("datasets/") + name)));
  }
}

TEST(PickleReader, RefusesHostileSavedStorages) {
  const auto error_of = [](const std::string& name) {
    return PickleError(testing::ReadFileBytes(DataPath("datasets/" + name)));
  };
  std::string error = error_of("tensor_view_beyond_storage.pkl");
  EXPECT_NE(error.find("inside its storage of 4 elements"), std::string::npos) << error;
  error = error_of("tensor_count_beyond_bytes.pkl");
  EXPECT_NE(error.find("4 stored elements"), std::string::npos) << error;
  error = error_of("tensor_evil_inner_global.pkl");
  EXPECT_NE(error.find("os.system"), std::string::npos) << error;
  EXPECT_NE(error.find("saved torch storage"), std::string::npos) << error;
  // Anything but torch.save bytes, and a truncated storage, fail by name.
  std::string bytes = testing::ReadFileBytes(DataPath("datasets/tensors_legacy_p4.pkl"));
  const size_t magic = bytes.find("\x8a\x0a\x6c\xfc"s);
  ASSERT_NE(magic, std::string::npos);
  std::string garbled = bytes;
  garbled[magic + 3] = 'x';
  error = PickleError(garbled);
  EXPECT_NE(error.find("legacy magic number"), std::string::npos) << error;
  // Every truncation of a tensor pickle fails cleanly (or decodes a shorter prefix).
  for (size_t n = 0; n < bytes.size(); n += 7) PickleError(bytes.substr(0, n));
  // The element count is checked against the byte budget before allocating.
  PickleLimits tight;
  tight.max_total_bytes = 64;
  error = PickleError(bytes, tight);
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace handlabel
