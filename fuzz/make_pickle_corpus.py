#!/usr/bin/python3
"""Writes the seed corpus of the pickle reader's fuzz target into corpus/pickle_reader/
and an object-array .npz for the npz target into corpus/npz_reader/ (whose other seeds
are copies of tests/data/npy files):
tiny pickles of every shape the reader understands (a MANO-structured Python 2 pickle
with chumpy / scipy objects, numpy._core re-saves at protocols 4 and 5, a torch.save
data.pkl, assorted values at protocols 0-5). Small inputs keep the fuzzer fast.

Run with /usr/bin/python3:  /usr/bin/python3 fuzz/make_pickle_corpus.py
"""
import collections
import io
import os
import pickle
import sys
import zipfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "data", "mano"))
import make_mano_fixtures as fx  # noqa: E402  (fake chumpy / scipy, picklers)

OUT = os.path.join(HERE, "corpus", "pickle_reader")


def save(name, data):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(data)


def dumps(obj, pickler, protocol):
    buf = io.BytesIO()
    pickler(buf, protocol).dump(obj)
    return buf.getvalue()


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(7)
    wide = rng.normal(size=(2, 3, 3))
    idxs = np.arange(wide.size).reshape(wide.shape)[:, :, :2].ravel()
    tiny = {
        "v_template": rng.normal(size=(2, 3)),
        "f": np.array([[0, 1, 1]], dtype=np.uint32),
        "shapedirs": fx.Select(fx.Ch(wide), idxs, (2, 3, 2)),
        "weights": fx.Ch(np.eye(2)),
        "J_regressor": fx.csc_matrix(np.array([[0.5, 0.0], [0.0, 1.0]])),
        "kintree_table": np.array([[4294967295, 0], [0, 1]], dtype=np.int64),
        "bs_style": "lbs",
    }
    save("fixture_py2_tiny.pkl", dumps(tiny, fx.Py2Pickler, 2))
    plain = {k: v for k, v in tiny.items() if isinstance(v, (np.ndarray, str))}
    plain["scalar"] = np.float32(1.5)
    plain["fortran"] = np.asfortranarray(rng.normal(size=(2, 2)))
    for p in (4, 5):
        save("resaved_p%d.pkl" % p, dumps(plain, fx.Numpy2Pickler, p))
    small = collections.OrderedDict([
        ("text", "h\xe9"), ("bytes", b"\x00\xff"), ("ints", (1, -1, 2**40)),
        ("float", 0.5), ("none", None), ("set", {1}), ("arr", np.arange(3.0))])
    for p in range(6):
        save("small_p%d.pkl" % p, pickle.dumps(small, protocol=p))
    with zipfile.ZipFile(os.path.join(ROOT, "tests", "data", "npy", "state_dict.pt")) as z:
        save("torch_data.pkl", z.read("state_dict/data.pkl"))
    import scipy.sparse
    sys.modules.pop("scipy.sparse.csc")  # the real class, as np.savez users have it
    np.savez(os.path.join(HERE, "corpus", "npz_reader", "object_array.npz"),
             J=np.array(scipy.sparse._csc.csc_matrix(np.eye(2)), dtype=object),
             v=np.arange(3.0))


if __name__ == "__main__":
    main()
