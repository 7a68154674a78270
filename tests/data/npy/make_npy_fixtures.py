#!/usr/bin/python3
"""Writes small .npy / .npz / zip files with numpy, zipfile and torch, for the C++
readers' tests (tests/formats/npy_test.cc, zip_test.cc, pickle_reader_test.cc).

Run with /usr/bin/python3 (Debian numpy; torch optional):
    /usr/bin/python3 make_npy_fixtures.py
Every array has shape (2, 3, 4) and logical (C-order) values given by value(kind, i)
for element i, so the tests can recompute them without any stored expectations.
"""
import io
import os
import zipfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHAPE = (2, 3, 4)


def values(dtype):
    i = np.arange(24)
    kind = np.dtype(dtype).kind
    if kind == "b":
        v = i % 3 == 0
    elif kind == "u":
        v = i * 3
    elif kind == "i":
        v = i * 5 - 40
    else:
        v = i * 1.25 - 7.0
    return v.astype(dtype).reshape(SHAPE)


def write(name, array, version=None):
    with open(os.path.join(HERE, name), "wb") as f:
        np.lib.format.write_array(f, array, version=version, allow_pickle=False)


def main():
    write("f8_c.npy", values("<f8"))
    write("f4_big.npy", values(">f4"))
    write("f2_little.npy", values("<f2"))
    write("i2_fortran.npy", np.asfortranarray(values("<i2")))
    write("i8_big_fortran.npy", np.asfortranarray(values(">i8")))
    write("u1.npy", values("u1"))
    write("u4_big.npy", values(">u4"))
    write("b1.npy", values("?"))
    write("i4_v2.npy", values("<i4"), version=(2, 0))
    write("f8_v3.npy", values("<f8"), version=(3, 0))
    write("unicode.npy", np.array("right"))
    write("scalar.npy", np.array(2.5))
    write("empty.npy", np.zeros((0, 3)))

    a, b = values("<f8"), values("<i4")
    np.savez(os.path.join(HERE, "stored.npz"), a=a, b=b)
    np.savez_compressed(os.path.join(HERE, "compressed.npz"), a=a, b=b)

    # zip64 records on a small archive, as large archives would have them.
    with zipfile.ZipFile(os.path.join(HERE, "zip64.zip"), "w") as z:
        for name, method in [("stored.npy", zipfile.ZIP_STORED),
                             ("deflated.npy", zipfile.ZIP_DEFLATED)]:
            buf = io.BytesIO()
            np.lib.format.write_array(buf, a)
            info = zipfile.ZipInfo(name)
            info.compress_type = method
            with z.open(info, "w", force_zip64=True) as f:
                f.write(buf.getvalue())

    try:
        import torch
    except ImportError:
        print("torch not available: torch fixtures skipped")
        return
    state = {
        "weight": torch.from_numpy(values("<f4")),
        "bias": torch.from_numpy(values("<f8")[0, 0]),
        "steps": torch.from_numpy(values("<i8").reshape(6, 4)).t()[1:],  # strided view, offset 1
        "half": torch.from_numpy(values("<f2")),
    }
    from collections import OrderedDict
    torch.save(OrderedDict(state), os.path.join(HERE, "state_dict.pt"))


if __name__ == "__main__":
    main()
