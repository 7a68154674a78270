#!/usr/bin/python3
"""Writes meta_0000.pkl, an HO3D v3 style per-frame annotation pickled by numpy (dict of
float32 arrays, a str and None values, pickle protocol 2), and expected.json: its
handJoints3D as a reader must return them, in OpenCV camera axes (diag(1, -1, -1) of
HO3D's OpenGL axes) and in the 21-point SNAP/OpenPose order (wrist, thumb 1-4, index
1-4, middle, ring, pinky), computed here from HO3D's joint names. No real data.
Run from this folder: /usr/bin/python3 make_meta_fixture.py
"""
import json
import pickle

import numpy as np

rng = np.random.default_rng(31)

# HO3D / MANO order: wrist, index 1-3, middle 1-3, pinky 1-3, ring 1-3, thumb 1-3, then
# the tips of thumb, index, middle, ring, pinky.
ho3d_names = ["wrist"]
for finger in ["index", "middle", "pinky", "ring", "thumb"]:
    ho3d_names += [f"{finger}{i}" for i in (1, 2, 3)]
ho3d_names += [f"{finger}4" for finger in ["thumb", "index", "middle", "ring", "pinky"]]
snap_names = ["wrist"]
for finger in ["thumb", "index", "middle", "ring", "pinky"]:
    snap_names += [f"{finger}{i}" for i in (1, 2, 3, 4)]

joints_gl = (rng.normal(size=(21, 3)) * 0.03 + [0.02, -0.01, -0.5]).astype(np.float32)
meta = {
    "camMat": np.array([[614.6, 0, 320.2], [0, 614.9, 238.7], [0, 0, 1]]),
    "handPose": rng.normal(size=48).astype(np.float32),
    "handTrans": np.array([0.02, -0.01, -0.5], dtype=np.float32),
    "handBeta": rng.normal(size=10).astype(np.float32),
    "handJoints3D": joints_gl,
    "handBoundingBox": None,
    "objName": "006_mustard_bottle",
    "objRot": rng.normal(size=(3, 1)).astype(np.float32),
}
with open("meta_0000.pkl", "wb") as f:
    pickle.dump(meta, f, protocol=2)

flip = np.diag([1.0, -1.0, -1.0])
joints_cv = joints_gl.astype(np.float64) @ flip.T
expected = [joints_cv[ho3d_names.index(n)].tolist() for n in snap_names]
with open("expected.json", "w") as f:
    json.dump({"keypoints_in_camera_snap": expected}, f, indent=1)
