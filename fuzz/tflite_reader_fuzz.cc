// libFuzzer target for the TFLite reader (network/detector/tflite_reader.h): the
// flatbuffers Verifier, then our index, shape and buffer-size checks. After a successful
// parse, every tensor's constant data and every operator's tensor indices are touched, so
// a range the checks missed shows up as an AddressSanitizer report. Anything but success
// or InputError is a finding. (The LibTorch interpreter is not built with sanitizers;
// it only sees graphs this reader accepted.)

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "network/detector/tflite_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const auto graph = handlabel::ParseTflite(std::move(bytes), "fuzz.tflite");
    unsigned sum = 0;
    for (const handlabel::TfliteTensor& t : graph->tensors) {
      const uint8_t* p = graph->data(t);
      for (size_t i = 0; p && i < t.data_size; ++i) sum += p[i];
      sum += static_cast<unsigned>(t.num_elements());
    }
    for (const handlabel::TfliteOp& op : graph->ops) {
      for (int i : op.inputs) sum += i >= 0 ? graph->tensors.at(i).shape.size() : 0;
      for (int i : op.outputs) sum += graph->tensors.at(i).shape.size();
    }
    for (int i : graph->inputs) sum += graph->tensors.at(i).shape.size();
    for (int i : graph->outputs) sum += graph->tensors.at(i).shape.size();
    volatile unsigned sink = sum;
    (void)sink;
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
