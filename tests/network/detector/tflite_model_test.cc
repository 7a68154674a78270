// The TFLite reader and interpreter as a whole: files written by a peer writer (flatc
// from JSON, fuzz/make_tflite_corpus.py), and every kind of bad input: malformed or
// truncated files, out-of-range indices and sizes, unsupported operators, wrong inputs.

#include <ATen/Parallel.h>
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <array>
#include <cmath>
#include <optional>
#include <thread>

#include "core/blas_library.h"
#include "core/errors.h"
#include "network/detector/tflite_model.h"
#include "network/detector/tflite_reader.h"
#include "tests/fuzz_replay.h"
#include "tests/network/detector/tflite_test_util.h"

namespace handlabel {
namespace {

using namespace testing_tflite;

std::string CorpusFile(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/fuzz/corpus/tflite_reader/" + name;
}

// A 1x4x4x2 -> conv 3x3 (3 channels) -> logistic model.
std::string SmallModel(int op_code = 3) {
  TfliteBuilder b;
  const int in = b.Tensor({1, 4, 4, 2}, "image");
  const int w = b.Constant({3, 3, 3, 2}, std::vector<float>(54, 0.1f));
  const int conv = b.Tensor({1, 4, 4, 3});
  b.Op(op_code, {in, w, -1}, {conv}, fb::BuiltinOptions_Conv2DOptions,
       fb::CreateConv2DOptions(b.fbb(), fb::Padding_SAME, 1, 1).Union());
  const int out = b.Tensor({1, 4, 4, 3}, "score");
  b.Op(14, {conv}, {out});
  return b.Finish({in}, {out});
}

// The message of the InputError `f` throws ("" and a test failure if none).
template <typename F>
std::string InputErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(TfliteModel, RunsAModelWrittenByFlatc) {
  // fp16_head: DEQUANTIZE -> depthwise 3x3 of 0.5 (SAME) -> PRELU -> MEAN(H, W) ->
  // FULLY_CONNECTED [1, -1] -> LOGISTIC. Input channel 0 = 1, channel 1 = 2: the 3x3
  // window sums over 4 corners x 4 + 4 edges x 6 + 1 centre x 9 = 49 cells, so the
  // means are 0.5 * 49 / 9 * (1, 2) and the output is sigmoid(-0.5 * 49 / 9).
  auto model = TfliteModel::Load(CorpusFile("fp16_head.tflite"));
  ASSERT_EQ(model->inputs().size(), 1u);
  EXPECT_EQ(model->inputs()[0].shape, (std::vector<int>{1, 3, 3, 2}));
  EXPECT_EQ(model->outputs()[0].shape, (std::vector<int>{1, 1}));
  EXPECT_EQ(model->op_names(),
            (std::vector<std::string>{"DEQUANTIZE", "DEPTHWISE_CONV_2D", "PRELU", "MEAN",
                                      "FULLY_CONNECTED", "LOGISTIC"}));
  std::vector<float> x;
  for (int i = 0; i < 9; ++i) x.insert(x.end(), {1.0f, 2.0f});
  const float want = 1.0f / (1.0f + std::exp(0.5f * 49.0f / 9.0f));
  EXPECT_NEAR(model->Run({x})[0][0], want, 1e-6f);
}

TEST(TfliteModel, RunsTheOtherFlatcSeeds) {
  for (const char* name : {"conv_pool.tflite", "resize_pad_concat.tflite"}) {
    auto model = TfliteModel::Load(CorpusFile(name));
    std::vector<std::vector<float>> inputs;
    for (const auto& info : model->inputs())
      inputs.emplace_back(info.num_elements(), 1.0f);
    const auto outputs = model->Run(inputs);
    ASSERT_EQ(outputs.size(), model->outputs().size()) << name;
    EXPECT_EQ(static_cast<int64_t>(outputs[0].size()),
              model->outputs()[0].num_elements());
  }
  // resize_pad_concat: a constant image stays constant through the half-pixel resize;
  // the channel pad adds zeros, ADD doubles: rows alternate (2, 0).
  auto model = TfliteModel::Load(CorpusFile("resize_pad_concat.tflite"));
  const auto out = model->Run({std::vector<float>(4, 1.0f)})[0];
  ASSERT_EQ(out.size(), 64u);
  for (size_t i = 0; i < out.size(); ++i)
    EXPECT_EQ(out[i], i % 2 == 0 ? 2.0f : 0.0f) << i;
}

TEST(TfliteModel, InfoAndInputChecks) {
  auto model = TfliteModel::FromBytes(SmallModel(), "small.tflite");
  EXPECT_EQ(model->inputs()[0].name, "image");
  EXPECT_EQ(model->outputs()[0].name, "score");
  EXPECT_EQ(model->inputs()[0].num_elements(), 32);
  const std::string wrong_size =
      InputErrorOf([&] { model->Run({std::vector<float>(31)}); });
  EXPECT_NE(wrong_size.find("input 0 (image)"), std::string::npos) << wrong_size;
  EXPECT_NE(wrong_size.find("32 floats (1x4x4x2)"), std::string::npos) << wrong_size;
  const std::string wrong_count = InputErrorOf([&] { model->Run({}); });
  EXPECT_NE(wrong_count.find("1 input tensors"), std::string::npos) << wrong_count;
  TfliteModelOptions options;
  options.num_threads = -1;
  EXPECT_THROW(TfliteModel::FromBytes(SmallModel(), "x", options), InputError);
  EXPECT_THROW(TfliteModel::Load("/nonexistent/model.tflite"), InputError);
}

// A model's thread count holds for its own calls only: loading and running it leave
// the caller's count, and the count new threads start with, as they were (the label
// job's network lanes run on the process-wide count while frames are detected on one
// thread each), and calls from several threads at once give the same answer.
TEST(TfliteModel, RunsOnItsThreadCountWithoutChangingAnyoneElses) {
  const int before = at::get_num_threads();
  at::set_num_threads(2);
  TfliteModelOptions options;
  options.num_threads = 1;
  auto model = TfliteModel::FromBytes(SmallModel(), "small.tflite", options);
  const std::vector<float> input(32, 0.5f);
  const std::vector<float> alone = model->Run({input})[0];
  EXPECT_EQ(at::get_num_threads(), 2);
  int new_thread_count = 0;
  std::thread([&] { new_thread_count = at::get_num_threads(); }).join();
  EXPECT_EQ(new_thread_count, 2);
  std::vector<std::vector<float>> answers(4);
  std::vector<std::thread> callers;
  for (auto& answer : answers) {
    callers.emplace_back([&] {
      answer = model->Run({input})[0];
      EXPECT_EQ(at::get_num_threads(), 2);  // this thread's own count, given back
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (const auto& answer : answers) EXPECT_EQ(answer, alone);
  at::set_num_threads(before);
}

// The models' 1x1 convolutions and fully connected layers are BLAS products (sgemm),
// called from every thread that detects a frame while other threads fit (LAPACK). With
// OpenBLAS's serial build such calls made at once returned wrong products (with this
// test's small products, which spend the most of their time where the threads' buffers
// collide: 1100-1300 wrong of 2 x 20000 in every run), so a detector job's labels
// changed from run to run. The program refuses such a BLAS (core/blas_library.h).
TEST(ConcurrentProducts, ProductsFromTwoThreadsAtOnceAreExact) {
  EXPECT_EQ(PrepareBlasForThreads(), std::nullopt) << LoadedBlasLibrary().name;
  torch::manual_seed(5);
  const torch::Tensor a = torch::randn({64, 64});
  const torch::Tensor b = torch::randn({64, 32});
  const torch::Tensor alone = torch::mm(a, b);
  std::array<int, 2> wrong{0, 0};
  std::vector<std::thread> callers;
  for (int t = 0; t < 2; ++t) {
    callers.emplace_back([&, t] {
      for (int i = 0; i < 20000; ++i) wrong[t] += !torch::equal(torch::mm(a, b), alone);
    });
  }
  for (std::thread& caller : callers) caller.join();
  EXPECT_EQ(wrong[0] + wrong[1], 0)
      << "of 2 x 20000 products, with " << LoadedBlasLibrary().name;
}

TEST(TfliteModel, NamesUnsupportedOperators) {
  const std::string message = InputErrorOf(
      [] { TfliteModel::FromBytes(SmallModel(/*SOFTMAX*/ 25), "soft.tflite"); });
  EXPECT_NE(message.find("soft.tflite"), std::string::npos) << message;
  EXPECT_NE(message.find("operator 0"), std::string::npos) << message;
  EXPECT_NE(message.find("SOFTMAX"), std::string::npos) << message;
}

TEST(TfliteModel, RejectsNonTfliteAndTruncatedFiles) {
  EXPECT_THROW(TfliteModel::FromBytes("", "empty"), InputError);
  EXPECT_THROW(TfliteModel::FromBytes("not a model at all", "text"), InputError);
  const std::string bytes = SmallModel();
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_THROW(ParseTflite(bytes.substr(0, n), "cut"), InputError) << n << " bytes";
  }
}

TEST(TfliteModel, ByteFlipsThrowInputErrorOrLoad) {
  const std::string bytes = SmallModel();
  std::mt19937 rng(21);
  std::uniform_int_distribution<size_t> position(0, bytes.size() - 1);
  std::uniform_int_distribution<int> value(0, 255);
  int rejected = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string bad = bytes;
    for (int k = 0; k < 3; ++k) bad[position(rng)] = static_cast<char>(value(rng));
    try {
      auto model = TfliteModel::FromBytes(bad, "flipped");
      std::vector<std::vector<float>> inputs;
      for (const auto& info : model->inputs())
        inputs.emplace_back(info.num_elements(), 0.5f);
      model->Run(inputs);
    } catch (const InputError&) {
      ++rejected;
    }  // any other exception fails the test
  }
  EXPECT_GT(rejected, 0);
}

TEST(TfliteModel, RejectsBadIndicesSizesAndShapes) {
  {  // a tensor pointing past the buffers
    TfliteBuilder b;
    const int in = b.Tensor({1, 2});
    const int c = b.Constant({1, 2}, {1, 2});
    b.SetBufferIndex(c, 99);
    const int out = b.Tensor({1, 2});
    b.Op(0, {in, c}, {out});
    const std::string m = InputErrorOf([&] { ParseTflite(b.Finish({in}, {out}), "m"); });
    EXPECT_NE(m.find("tensor 1 buffer"), std::string::npos) << m;
  }
  {  // constant data shorter than its shape
    TfliteBuilder b;
    const int in = b.Tensor({1, 3});
    const int c = b.Constant({1, 3}, {1, 2});
    const int out = b.Tensor({1, 3});
    b.Op(0, {in, c}, {out});
    const std::string m = InputErrorOf([&] { ParseTflite(b.Finish({in}, {out}), "m"); });
    EXPECT_NE(m.find("12 bytes"), std::string::npos) << m;
  }
  {  // an operator input past the tensors
    TfliteBuilder b;
    const int in = b.Tensor({1, 2});
    const int out = b.Tensor({1, 2});
    b.Op(0, {in, 7}, {out});
    const std::string m = InputErrorOf([&] { ParseTflite(b.Finish({in}, {out}), "m"); });
    EXPECT_NE(m.find("operator 0 inputs"), std::string::npos) << m;
  }
  {  // a negative dimension
    TfliteBuilder b;
    const int in = b.Tensor({1, -2});
    const std::string m = InputErrorOf([&] { ParseTflite(b.Finish({in}, {in}), "m"); });
    EXPECT_NE(m.find("shape"), std::string::npos) << m;
  }
  {  // a declared output shape that the operator does not produce
    TfliteBuilder b;
    const int in = b.Tensor({1, 4, 4, 2});
    const int w = b.Constant({3, 1, 1, 2}, std::vector<float>(6, 1.0f));
    const int out = b.Tensor({1, 4, 4, 5});
    b.Op(3, {in, w, -1}, {out}, fb::BuiltinOptions_Conv2DOptions,
         fb::CreateConv2DOptions(b.fbb(), fb::Padding_SAME, 1, 1).Union());
    const std::string m =
        InputErrorOf([&] { TfliteModel::FromBytes(b.Finish({in}, {out}), "m"); });
    EXPECT_NE(m.find("operator 0 (CONV_2D)"), std::string::npos) << m;
    EXPECT_NE(m.find("1x4x4x5"), std::string::npos) << m;
  }
  {  // weights computed at run time
    TfliteBuilder b;
    const int in = b.Tensor({1, 4, 4, 2});
    const int w = b.Tensor({3, 1, 1, 2});
    const int out = b.Tensor({1, 4, 4, 3});
    b.Op(3, {in, w, -1}, {out}, fb::BuiltinOptions_Conv2DOptions,
         fb::CreateConv2DOptions(b.fbb(), fb::Padding_SAME, 1, 1).Union());
    const std::string m = InputErrorOf([&] {
      TfliteModel::FromBytes(b.Finish({in, w}, {out}), "m");
    });
    EXPECT_NE(m.find("constant data"), std::string::npos) << m;
  }
  {  // an output that no operator writes
    TfliteBuilder b;
    const int in = b.Tensor({1, 2});
    const int out = b.Tensor({1, 2}, "orphan");
    const std::string m =
        InputErrorOf([&] { TfliteModel::FromBytes(b.Finish({in}, {out}), "m"); });
    EXPECT_NE(m.find("orphan"), std::string::npos) << m;
  }
  {  // int8 activations (quantized models)
    TfliteBuilder b;
    const int in = b.Tensor({1, 2}, "q", fb::TensorType_INT8);
    const std::string m =
        InputErrorOf([&] { TfliteModel::FromBytes(b.Finish({in}, {in}), "m"); });
    EXPECT_NE(m.find("INT8"), std::string::npos) << m;
  }
}

// A NaN or infinite weight made every answer NaN (a palm model with NaN weights found
// "no hand" everywhere): refused at load, naming the tensor and the first bad element.
TEST(TfliteModel, NonFiniteWeightsAreRefusedNamingTheTensor) {
  for (const float bad : {std::nanf(""), INFINITY}) {
    TfliteBuilder b;
    const int in = b.Tensor({1, 4, 4, 2}, "image");
    std::vector<float> weights(54, 0.1f);
    weights[7] = bad;
    const int w = b.Constant({3, 3, 3, 2}, weights);
    const int out = b.Tensor({1, 4, 4, 3}, "score");
    b.Op(3, {in, w, -1}, {out}, fb::BuiltinOptions_Conv2DOptions,
         fb::CreateConv2DOptions(b.fbb(), fb::Padding_SAME, 1, 1).Union());
    const std::string m =
        InputErrorOf([&] { TfliteModel::FromBytes(b.Finish({in}, {out}), "m.tflite"); });
    EXPECT_NE(m.find("m.tflite: field 'tensor 1 ("), std::string::npos) << m;
    EXPECT_NE(m.find("expected finite weights"), std::string::npos) << m;
    EXPECT_NE(m.find("1 of 54 values NaN or infinite, the first at element 7"),
              std::string::npos)
        << m;
  }
  EXPECT_NO_THROW(TfliteModel::FromBytes(SmallModel(), "m.tflite"));
}

// The kept corpus of tflite_reader_fuzz (docs/fuzzing.md) through the reader the
// target feeds, with seeded edits, touching what the target touches: every input parses
// or is an InputError. (Each other corpus has its own *FuzzCorpusSmoke test.)
TEST(TfliteModel, FuzzCorpusSmoke) {
  EXPECT_GE(testing::ReplayFuzzCorpus(
                "tflite_reader",
                [](const std::string& bytes) {
                  const auto graph = ParseTflite(bytes, "corpus.tflite");
                  size_t sum = 0;
                  for (const TfliteTensor& t : graph->tensors) {
                    const uint8_t* p = graph->data(t);
                    for (size_t i = 0; p && i < t.data_size; ++i) sum += p[i];
                  }
                  for (const TfliteOp& op : graph->ops) {
                    for (int i : op.inputs)
                      sum += i >= 0 ? graph->tensors.at(i).shape.size() : 0;
                    for (int i : op.outputs) sum += graph->tensors.at(i).shape.size();
                  }
                  volatile size_t touched = sum;  // kept: the reads must happen
                  (void)touched;
                },
                /*edits=*/5),
            100);
}

TEST(TfliteModel, RunIsThreadSafe) {
  auto model = TfliteModel::FromBytes(SmallModel(), "small.tflite");
  std::vector<float> x(32);
  for (size_t i = 0; i < x.size(); ++i) x[i] = 0.1f * static_cast<float>(i % 7);
  const auto want = model->Run({x});
  std::vector<std::vector<std::vector<float>>> got(4);
  std::vector<std::thread> threads;
  for (auto& g : got) threads.emplace_back([&] { g = model->Run({x}); });
  for (auto& t : threads) t.join();
  for (const auto& g : got) EXPECT_EQ(g, want);
}

}  // namespace
}  // namespace handlabel
