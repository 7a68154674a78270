#!/usr/bin/env python3
"""Writes the named seeds of fuzz/corpus/tflite_reader/: small TFLite models described
as JSON and compiled to binary by flatc with our schema subset (network/detector/tflite_schema.fbs).
Standard library + flatc only.  Usage: fuzz/make_tflite_corpus.py [OUT_DIR]"""
import json
import os
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCHEMA = os.path.join(ROOT, "network", "tflite_schema.fbs")


def floats(values):
    return list(struct.pack("<%df" % len(values), *values))


def ints(values):
    return list(struct.pack("<%di" % len(values), *values))


def halves(values):
    return list(struct.pack("<%de" % len(values), *values))


class Model:
    def __init__(self):
        self.buffers = [{}]
        self.tensors = []
        self.ops = []
        self.codes = []

    def tensor(self, shape, type_="FLOAT32", data=None):
        buffer = 0
        if data is not None:
            self.buffers.append({"data": data})
            buffer = len(self.buffers) - 1
        self.tensors.append({"shape": shape, "type": type_, "buffer": buffer,
                             "name": "t%d" % len(self.tensors)})
        return len(self.tensors) - 1

    def op(self, code, inputs, outputs, options_type=None, options=None):
        if code not in self.codes:
            self.codes.append(code)
        op = {"opcode_index": self.codes.index(code), "inputs": inputs, "outputs": outputs}
        if options_type:
            op["builtin_options_type"] = options_type
            op["builtin_options"] = options or {}
        self.ops.append(op)

    def json(self, inputs, outputs):
        return {"version": 3,
                "operator_codes": [{"deprecated_builtin_code": min(c, 127), "builtin_code": c}
                                   for c in self.codes],
                "subgraphs": [{"tensors": self.tensors, "inputs": inputs, "outputs": outputs,
                               "operators": self.ops}],
                "buffers": self.buffers}


def conv_model():
    m = Model()
    x = m.tensor([1, 4, 4, 2])
    w = m.tensor([3, 3, 3, 2], data=floats([0.01 * i for i in range(54)]))
    b = m.tensor([3], data=floats([0.1, 0.2, 0.3]))
    y = m.tensor([1, 2, 2, 3])
    m.op(3, [x, w, b], [y], "Conv2DOptions",
         {"padding": "SAME", "stride_w": 2, "stride_h": 2, "fused_activation_function": "RELU6"})
    z = m.tensor([1, 1, 1, 3])
    m.op(17, [y], [z], "Pool2DOptions",
         {"padding": "VALID", "stride_w": 2, "stride_h": 2, "filter_width": 2, "filter_height": 2})
    return m.json([x], [z])


def fp16_model():
    m = Model()
    x = m.tensor([1, 3, 3, 2])
    wh = m.tensor([1, 3, 3, 2], "FLOAT16", halves([0.5] * 18))
    w = m.tensor([1, 3, 3, 2])
    m.op(6, [wh], [w])
    y = m.tensor([1, 3, 3, 2])
    m.op(4, [x, w, -1], [y], "DepthwiseConv2DOptions",
         {"stride_w": 1, "stride_h": 1, "depth_multiplier": 1})
    a = m.tensor([1, 1, 2], data=floats([0.25, 0.5]))
    p = m.tensor([1, 3, 3, 2])
    m.op(54, [y, a], [p])
    axes = m.tensor([2], "INT32", ints([1, 2]))
    mean = m.tensor([1, 2])
    m.op(40, [p, axes], [mean], "ReducerOptions", {"keep_dims": False})
    fw = m.tensor([1, 2], data=floats([1.0, -1.0]))
    out = m.tensor([1, 1])
    m.op(9, [mean, fw, -1], [out], "FullyConnectedOptions", {})
    s = m.tensor([1, 1])
    m.op(14, [out], [s])
    return m.json([x], [s])


def resize_model():
    m = Model()
    x = m.tensor([1, 2, 2, 1])
    size = m.tensor([2], "INT32", ints([4, 4]))
    r = m.tensor([1, 4, 4, 1])
    m.op(23, [x, size], [r], "ResizeBilinearOptions", {"half_pixel_centers": True})
    pads = m.tensor([4, 2], "INT32", ints([0, 0, 0, 0, 0, 0, 0, 1]))
    p = m.tensor([1, 4, 4, 2])
    m.op(34, [r, pads], [p], "PadOptions", {})
    q = m.tensor([1, 4, 4, 2])
    m.op(0, [p, p], [q], "AddOptions", {})
    shape = m.tensor([3], "INT32", ints([1, 16, 2]))
    a = m.tensor([1, 16, 2])
    m.op(22, [q, shape], [a])
    c = m.tensor([1, 32, 2])
    m.op(2, [a, a], [c], "ConcatenationOptions", {"axis": 1})
    return m.json([x], [c])


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "fuzz", "corpus", "tflite_reader")
    os.makedirs(out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name, model in [("conv_pool", conv_model()), ("fp16_head", fp16_model()),
                            ("resize_pad_concat", resize_model())]:
            path = os.path.join(tmp, name + ".json")
            with open(path, "w") as f:
                json.dump(model, f)
            subprocess.run(["flatc", "-b", "-o", tmp, SCHEMA, path], check=True)
            os.replace(os.path.join(tmp, name + ".tflite"), os.path.join(out, name + ".tflite"))
            print("wrote", os.path.join(out, name + ".tflite"))


if __name__ == "__main__":
    main()
