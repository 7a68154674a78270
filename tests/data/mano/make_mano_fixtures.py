#!/usr/bin/python3
"""Writes small made-up hand models with exactly the structure of the official MANO
files, in every format LoadHandModel reads, plus the NumPy LBS forward pass of the
model for a few parameter sets. No MANO data is involved: all values are random.

Run with /usr/bin/python3 (Debian numpy, scipy):  /usr/bin/python3 make_mano_fixtures.py

Outputs (all of one model, 12 vertices, 10 betas, right hand):
  mano_py2_right.pkl     as the official MANO_RIGHT.pkl: a Python 2 protocol-2 pickle.
                         numpy buffers and str keys are Python 2 `str`
                         (SHORT_BINSTRING / BINSTRING, not Python 3's _codecs.encode),
                         shapedirs is a chumpy.reordering.Select over a chumpy.ch.Ch,
                         weights a chumpy.ch.Ch, J_regressor a scipy.sparse.csc
                         csc_matrix. chumpy and the old scipy module are faked here and
                         registered under their real module names, so the pickle holds
                         the real globals.
  mano_resaved_p4_right.pkl / _p5_right.pkl
                         a re-saved copy (no chumpy, real scipy csc_matrix) at protocol
                         4 / 5 with numpy 2's numpy._core names.
  mano_smplx_right.npz   np.savez_compressed with smplx-style keys, dense J_regressor.
  mano_smplx_object_right.npz
                         np.savez with J_regressor kept as a pickled csc_matrix object
                         array (what np.savez(**model) makes of a sparse matrix).
  expected.json          the model's arrays (values rounded so JSON is exact), the
                         fingertip ids, and LBS outputs for several parameter sets.
  small_p0..p5.pkl       one small dict of assorted values at protocols 0-5, for the
                         pickle reader's own tests.
"""
import collections
import io
import json
import os
import pickle
import struct
import sys
import types

import numpy as np
import scipy.sparse

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "lbs"))
from make_lbs_fixture import lbs  # noqa: E402  (independent NumPy LBS)

NUM_VERTS = 12
NUM_BETAS = 10
PARENTS = [-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14]


# ---- fake chumpy and Python-2-era scipy, registered under the real module names ----
def fake_module(name):
    module = types.ModuleType(name)
    sys.modules[name] = module
    return module


fake_module("chumpy")
ch_module = fake_module("chumpy.ch")
reordering_module = fake_module("chumpy.reordering")
scipy_csc_module = fake_module("scipy.sparse.csc")  # replaces scipy's deprecated alias


class Ch(object):
    """Pickles like chumpy.ch.Ch: NEWOBJ + its __getstate__ dict."""

    def __init__(self, x):
        self.__dict__.update({"_dirty_vars": set(), "_itr": None, "_make_dense": False,
                              "_make_sparse": False, "_depends_on_deps": {}, "x": x})


class Select(object):
    """chumpy.reordering.Select: value = a.r.ravel()[idxs].reshape(preferred_shape)."""

    def __init__(self, a, idxs, preferred_shape):
        self.__dict__.update({"_dirty_vars": {"a", "idxs"}, "_itr": None,
                              "_make_dense": False, "_make_sparse": False,
                              "_depends_on_deps": {}, "a": a, "idxs": idxs,
                              "preferred_shape": preferred_shape})


class csc_matrix(object):
    """scipy 0.x csc_matrix state: _shape, maxprint, data, indices, indptr."""

    def __init__(self, m):
        m = scipy.sparse.csc_matrix(m)
        self.__dict__.update({"_shape": m.shape, "maxprint": 50, "indices": m.indices,
                              "indptr": m.indptr, "data": m.data})


for cls, module in [(Ch, ch_module), (Select, reordering_module),
                    (csc_matrix, scipy_csc_module)]:
    cls.__module__ = module.__name__
    setattr(module, cls.__name__, cls)


class Py2Pickler(pickle._Pickler):
    """Protocol 2 as Python 2 wrote it: str and bytes are Python 2 `str` objects
    (SHORT_BINSTRING / BINSTRING), numpy dtypes reduce with int flags."""

    dispatch = pickle._Pickler.dispatch.copy()

    def save_py2_str(self, obj):
        data = obj if isinstance(obj, bytes) else obj.encode("latin1")
        if len(data) < 256:
            self.write(pickle.SHORT_BINSTRING + bytes([len(data)]) + data)
        else:
            self.write(pickle.BINSTRING + struct.pack("<i", len(data)) + data)
        self.memoize(obj)

    dispatch[bytes] = save_py2_str
    dispatch[str] = save_py2_str

    def reducer_override(self, obj):
        if isinstance(obj, np.dtype):
            cls, (descr, align, copy), state = obj.__reduce__()
            return cls, (descr, int(align), int(copy)), state
        return NotImplemented


# ---- numpy 2 names (numpy._core) for re-saved pickles, written with numpy 1.x -------
def alias(module_name, name, target):
    def stub(*args):
        return target(*args)

    module = sys.modules.get(module_name) or fake_module(module_name)
    stub.__module__, stub.__name__, stub.__qualname__ = module_name, name, name
    setattr(module, name, stub)
    return stub


fake_module("numpy._core")
RECONSTRUCT = alias("numpy._core.multiarray", "_reconstruct",
                    np.core.multiarray._reconstruct)
SCALAR = alias("numpy._core.multiarray", "scalar", np.core.multiarray.scalar)
FROMBUFFER = alias("numpy._core.numeric", "_frombuffer", np.core.numeric._frombuffer)
RENAMES = {np.core.multiarray._reconstruct: RECONSTRUCT,
           np.core.multiarray.scalar: SCALAR, np.core.numeric._frombuffer: FROMBUFFER}


class Numpy2Pickler(pickle.Pickler):
    def reducer_override(self, obj):
        if isinstance(obj, (np.ndarray, np.generic)):
            reduced = obj.__reduce_ex__(self.protocol_number)
            return (RENAMES.get(reduced[0], reduced[0]),) + tuple(reduced[1:])
        return NotImplemented

    def __init__(self, f, protocol):
        super().__init__(f, protocol=protocol)
        self.protocol_number = protocol


# ---- the model ----------------------------------------------------------------------
def make_model(rng):
    nv = NUM_VERTS
    r = lambda a, d=4: np.round(a, d)  # noqa: E731  short decimals keep JSON exact
    m = {}
    m["v_template"] = r(rng.uniform(-0.08, 0.08, (nv, 3)))
    faces = [rng.choice(nv, 3, replace=False) for _ in range(16)]
    m["f"] = np.array(faces, dtype=np.uint32)
    m["shapedirs"] = r(rng.normal(0, 0.01, (nv, 3, NUM_BETAS)))
    m["posedirs"] = r(rng.normal(0, 0.01, (nv, 3, 135)))
    reg = np.zeros((16, nv))
    for j in range(16):
        ids = rng.choice(nv, 4, replace=False)
        w = r(rng.uniform(0.1, 1.0, 4), 3)
        reg[j, ids] = w
    m["J_regressor"] = reg
    weights = np.zeros((nv, 16))
    for v in range(nv):
        count = rng.integers(1, 5)
        weights[v, rng.choice(16, count, replace=False)] = r(rng.uniform(0.1, 1, count), 3)
    m["weights"] = weights
    kintree = np.array([PARENTS, list(range(16))], dtype=np.int64)
    kintree[0, 0] = 4294967295  # MANO stores the root's parent as uint32 -1
    m["kintree_table"] = kintree
    m["J"] = reg @ m["v_template"]
    m["hands_components"] = r(rng.normal(0, 0.5, (45, 45)))
    m["hands_mean"] = r(rng.normal(0, 0.2, 45))
    m["hands_coeffs"] = r(rng.normal(0, 1, (6, 45)))
    m["bs_style"] = "lbs"
    m["bs_type"] = "lrotmin"
    return m


def official_layout(m):
    """The dict as the official pickle holds it (chumpy / old scipy objects)."""
    d = dict(m)
    nv = NUM_VERTS
    # shapedirs: a Select picking [:, :, :10] out of a wider Ch, as MANO's loader does.
    wide = np.concatenate([m["shapedirs"], np.full((nv, 3, 2), 7.0)], axis=2)
    idxs = np.arange(wide.size).reshape(wide.shape)[:, :, :NUM_BETAS].ravel()
    d["shapedirs"] = Select(Ch(wide), idxs, (nv, 3, NUM_BETAS))
    d["weights"] = Ch(m["weights"])
    d["J_regressor"] = csc_matrix(m["J_regressor"])
    return d


def resaved_layout(m):
    d = dict(m)
    d["J_regressor"] = scipy.sparse.csc_matrix(m["J_regressor"])
    return d


def write_pickle(name, obj, pickler, protocol):
    buf = io.BytesIO()
    pickler(buf, protocol).dump(obj)
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(buf.getvalue())


def main():
    rng = np.random.default_rng(20261129)
    model = make_model(rng)
    tips = rng.choice(NUM_VERTS, 5, replace=False)

    write_pickle("mano_py2_right.pkl", official_layout(model), Py2Pickler, 2)
    for p in (4, 5):
        write_pickle("mano_resaved_p%d_right.pkl" % p, resaved_layout(model),
                     Numpy2Pickler, p)
    arrays = {k: v for k, v in model.items() if isinstance(v, np.ndarray)}
    np.savez_compressed(os.path.join(HERE, "mano_smplx_right.npz"), **arrays)
    objects = dict(arrays)
    objects["J_regressor"] = np.array(scipy.sparse.csc_matrix(model["J_regressor"]),
                                      dtype=object)
    np.savez(os.path.join(HERE, "mano_smplx_object_right.npz"), **objects)

    # The Python 2 pickle must hold Python 2 str buffers and the real globals.
    raw = open(os.path.join(HERE, "mano_py2_right.pkl"), "rb").read()
    assert b"_codecs" not in raw and pickle.BINSTRING in raw
    for g in [b"chumpy.ch\nCh", b"chumpy.reordering\nSelect", b"scipy.sparse.csc\ncsc_matrix",
              b"numpy.core.multiarray\n_reconstruct", b"__builtin__\nset"]:
        assert g in raw, g

    flat = dict(model)
    lbs_model = {"v_template": model["v_template"],
                 "shapedirs": model["shapedirs"].reshape(3 * NUM_VERTS, NUM_BETAS),
                 "posedirs": model["posedirs"].reshape(3 * NUM_VERTS, 135),
                 "J_regressor": model["J_regressor"], "weights": model["weights"],
                 "tip_vertex_ids": tips}
    cases = []
    for k in range(4):
        orient = rng.normal(0, 0.6, 3) if k else np.zeros(3)
        pose = rng.normal(0, 0.5, 45) if k else np.zeros(45)
        betas = rng.normal(0, 1.0, NUM_BETAS)
        transl = rng.normal(0, 0.2, 3)
        verts, joints, kps = lbs(lbs_model, orient, pose, betas, transl)
        cases.append(dict(global_orient=orient.tolist(), hand_pose=pose.tolist(),
                          betas=betas.tolist(), transl=transl.tolist(),
                          vertices=verts.tolist(), joints=joints.tolist(),
                          keypoints=kps.tolist()))
    out = dict(comment="Generated by make_mano_fixtures.py; random values, not MANO.",
               model={k: (v.tolist() if isinstance(v, np.ndarray) else v)
                      for k, v in flat.items()},
               parents=PARENTS, tip_vertex_ids=tips.tolist(), cases=cases)
    with open(os.path.join(HERE, "expected.json"), "w") as f:
        json.dump(out, f, separators=(",", ":"))

    small = collections.OrderedDict([
        ("arr", np.arange(6, dtype="<f8").reshape(2, 3) * 1.5),
        ("big", np.array([1, -2, 3], dtype=">i4")),
        ("fortran", np.asfortranarray(np.arange(6, dtype="<i2").reshape(2, 3))),
        ("text", "h\xe9llo \u2603"),
        ("bytes", b"\x00\xff\n"),
        ("ints", (0, 1, -1, 255, 256, 65536, -2**31, 2**40, -2**63, 2**63 - 1)),
        ("float", 0.1),
        ("none", None),
        ("flags", [True, False]),
        ("set", {3}),
        ("od", collections.OrderedDict([("k", 1)])),
        ("scalar", np.float64(2.5)),
        ("nested", [[1, [2, []]], {}]),
    ])
    for p in range(6):
        with open(os.path.join(HERE, "small_p%d.pkl" % p), "wb") as f:
            pickle.dump(dict(small), f, protocol=p)
    print("sizes:", {n: os.path.getsize(os.path.join(HERE, n)) for n in sorted(os.listdir(HERE))})


if __name__ == "__main__":
    main()
