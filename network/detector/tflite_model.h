#pragma once
// A TFLite flatbuffer model (e.g. MediaPipe's hand landmark and palm detection models)
// run by our own LibTorch interpreter, behind a torch-free interface.
//
// I/O is float32, row-major, in TFLite's layout (images NHWC). The file is verified
// (flatbuffers Verifier, tensor/buffer index and size checks) and every operator is
// checked to be supported when the model is loaded; weights are dequantised and
// prepacked once there, so Run only executes the graph. Run is const and may be called
// from several threads at once (it keeps no state between calls).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace handlabel {

struct TfliteTensorInfo {
  std::string name;        // the tensor's name in the file (e.g. "input_1")
  std::vector<int> shape;  // e.g. {1, 224, 224, 3}
  // Number of floats: the product of shape.
  int64_t num_elements() const;
};

struct TfliteModelOptions {
  // LibTorch intra-op threads each Run uses, set for the calling thread during the
  // call only (other threads and the process-wide setting are left alone); 0 = the
  // calling thread's setting (by default the machine's hardware threads).
  int num_threads = 0;
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

class TfliteModel {
 public:
  // Reads and verifies a .tflite file. Throws InputError naming the file and what is
  // wrong: unreadable, not a TFLite flatbuffer, out-of-range indices or buffer sizes,
  // unsupported operator (named) or tensor type.
  static std::unique_ptr<TfliteModel> Load(const std::string& path,
                                           const TfliteModelOptions& options = {});
  // The same from bytes in memory; `source` names them in errors.
  static std::unique_ptr<TfliteModel> FromBytes(const std::string& bytes,
                                                const std::string& source,
                                                const TfliteModelOptions& options = {});
  virtual ~TfliteModel() = default;

  virtual const std::vector<TfliteTensorInfo>& inputs() const = 0;
  virtual const std::vector<TfliteTensorInfo>& outputs() const = 0;
  // The builtin operator names the graph uses, once each, in first-use order
  // (e.g. "CONV_2D").
  virtual std::vector<std::string> op_names() const = 0;

  // Runs the graph: one float vector per input (row-major, sizes as inputs()); returns
  // one vector per output (as outputs()). Throws InputError when the input count or a
  // size is wrong.
  virtual std::vector<std::vector<float>> Run(
      const std::vector<std::vector<float>>& inputs) const = 0;
};

}  // namespace handlabel
