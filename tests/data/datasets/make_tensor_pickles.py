#!/usr/bin/python3
"""Writes the torch-tensor pickles of tests/formats/pickle_reader_test.cc: tensors pickled
with plain pickle (as OakInk's anno/general_info/*.pkl hold them), whose storages are
torch.storage._load_from_bytes(<torch.save bytes>), in the legacy form torch writes
and in the zip form; plus hostile variants. Needs Debian's python3-torch.
Run from this folder: /usr/bin/python3 make_tensor_pickles.py
"""
import io
import pickle
from collections import OrderedDict

import torch


def values():
    base = torch.arange(24, dtype=torch.float64).reshape(4, 6) * 0.25 - 2
    return {
        "f32": torch.arange(9, dtype=torch.float32).reshape(3, 3) / 8,
        "f64_transposed": base.t(),                      # strides (1, 6)
        "f64_offset": base[1:, 2:4],                     # storage offset 8, strides (6, 1)
        "i64": torch.tensor([-3, 0, 7, 1 << 40], dtype=torch.int64),
        "f16": torch.tensor([0.5, -1.25, 3.0], dtype=torch.float16),
        "u8": torch.tensor([[0, 255], [7, 9]], dtype=torch.uint8),
        "scalar": torch.tensor(2.5),
        "nested": {"list": [torch.ones(2, dtype=torch.float32)], "n": 3},
    }


class ZipStorage:
    """Pickles as _load_from_bytes(<torch.save zip bytes of the storage>)."""

    def __init__(self, storage, saved=None):
        self.storage = storage
        self.saved = saved

    def __reduce__(self):
        if self.saved is None:
            b = io.BytesIO()
            torch.save(self.storage, b, _use_new_zipfile_serialization=True)
            self.saved = b.getvalue()
        return (torch.storage._load_from_bytes, (self.saved,))


class Tensor:
    """Pickles like a tensor: _rebuild_tensor_v2(storage, offset, size, stride, ...)."""

    def __init__(self, storage, offset, size, stride):
        self.args = (storage, offset, tuple(size), tuple(stride), False, OrderedDict())

    def __reduce__(self):
        return (torch._utils._rebuild_tensor_v2, self.args)


def zip_form(v):
    if isinstance(v, torch.Tensor):
        return Tensor(ZipStorage(v.storage()), v.storage_offset(), v.size(), v.stride())
    if isinstance(v, dict):
        return {k: zip_form(x) for k, x in v.items()}
    if isinstance(v, list):
        return [zip_form(x) for x in v]
    return v


def legacy_bytes(storage):
    b = io.BytesIO()
    torch.save(storage, b, _use_new_zipfile_serialization=False)
    return b.getvalue()


def write(name, obj, protocol=4):
    data = pickle.dumps(obj, protocol=protocol)
    loaded = pickle.loads(data)  # what Python itself makes of it (hostile ones fail)
    with open(name, "wb") as f:
        f.write(data)
    return loaded


# Good ones: torch's own pickling (legacy bytes inside), protocols 2 and 4, and the zip form.
for protocol in (2, 4):
    back = write(f"tensors_legacy_p{protocol}.pkl", values(), protocol)
    assert torch.equal(back["f64_transposed"], values()["f64_transposed"])
back = write("tensors_zip.pkl", zip_form(values()))
assert torch.equal(back["f64_offset"], values()["f64_offset"])

# Hostile: a view beyond its storage (torch itself would read out of bounds or fail).
small = torch.arange(4, dtype=torch.float32).storage()
data = pickle.dumps(Tensor(ZipStorage(small), 2, (3,), (1,)), protocol=4)
open("tensor_view_beyond_storage.pkl", "wb").write(data)
# Hostile: legacy bytes whose element count claims more than the bytes present.
saved = bytearray(legacy_bytes(torch.arange(4, dtype=torch.float32).storage()))
count_at = len(saved) - 4 * 4 - 8
assert saved[count_at] == 4
saved[count_at] = 200
data = pickle.dumps(Tensor(ZipStorage(None, bytes(saved)), 0, (4,), (1,)), protocol=4)
open("tensor_count_beyond_bytes.pkl", "wb").write(data)
# Hostile: the saved storage's own pickle calls os.system.
saved = legacy_bytes(torch.arange(4, dtype=torch.float32).storage())
evil = saved.replace(b"ctorch\nFloatStorage\n", b"cos\nsystem\n")
assert evil != saved
data = pickle.dumps(Tensor(ZipStorage(None, evil), 0, (4,), (1,)), protocol=4)
open("tensor_evil_inner_global.pkl", "wb").write(data)
