#!/usr/bin/python3
"""Writes small calibration fixtures in the documented layouts of DexYCB, HO3D v3 and
OakInk-Image (docs/cameras.md; no real data), plus truth.json: for every fixture the
camera names, intrinsics and cam_from_world (3x4, row-major) that a correct reader must
produce. Run from this folder: /usr/bin/python3 make_dataset_fixtures.py
"""
import json
import os
import pickle

import numpy as np
from scipy.spatial.transform import Rotation

rng = np.random.default_rng(8)


def random_pose():
    """A 4x4 rigid transform."""
    t = np.eye(4)
    t[:3, :3] = Rotation.from_rotvec(rng.normal(size=3) * 0.8).as_matrix()
    t[:3, 3] = rng.uniform(-1, 1, size=3)
    return t


def intrinsics():
    return dict(fx=float(rng.uniform(600, 640)), fy=float(rng.uniform(600, 640)),
                ppx=float(rng.uniform(310, 330)), ppy=float(rng.uniform(230, 250)))


truth = {}

# DexYCB: intrinsics per serial, extrinsics (camera -> common, 3x4 row-major), master.
serials = ["836212060125", "839512060362", "840412060917"]
calib_id = "20200709-subject-01"
os.makedirs("dexycb/calibration/intrinsics", exist_ok=True)
os.makedirs(f"dexycb/calibration/extrinsics_{calib_id}", exist_ok=True)
os.makedirs("dexycb/20200709-subject-01/20200709_141754", exist_ok=True)
cams = []
extr_lines = []
for s in serials:
    k = intrinsics()
    with open(f"dexycb/calibration/intrinsics/{s}_640x480.yml", "w") as f:
        f.write("color:\n")
        for key in ("fx", "fy", "ppx", "ppy"):
            f.write(f"  {key}: {k[key]!r}\n")
        f.write("depth:\n  fx: 380.0\n  fy: 380.0\n  ppx: 320.0\n  ppy: 240.0\n")
    # A second colour size, first in name order, with other values: readers must take
    # 640x480, as the toolkit does.
    with open(f"dexycb/calibration/intrinsics/{s}_1280x720.yml", "w") as f:
        f.write("color:\n")
        for key in ("fx", "fy", "ppx", "ppy"):
            f.write(f"  {key}: {2 * k[key]!r}\n")
    common_from_cam = random_pose()
    if s == serials[0]:
        common_from_cam = np.eye(4)  # the master camera defines the common frame
    values = ", ".join(repr(float(v)) for v in common_from_cam[:3].reshape(-1))
    extr_lines.append(f"  '{s}': [{values}]\n")
    cam_from_world = np.linalg.inv(common_from_cam)[:3]
    cams.append(dict(name=s, params=[k["fx"], k["fy"], k["ppx"], k["ppy"]],
                     width=640, height=480,
                     cam_from_world=cam_from_world.reshape(-1).tolist()))
tag = random_pose()  # the AprilTag's pose in the common frame: not a camera
extr_lines.append("  apriltag: [" + ", ".join(repr(float(v)) for v in tag[:3].reshape(-1)) +
                  "]\n")
with open(f"dexycb/calibration/extrinsics_{calib_id}/extrinsics.yml", "w") as f:
    f.write("extrinsics:\n" + "".join(extr_lines) + f"master: '{serials[0]}'\n")
with open("dexycb/20200709-subject-01/20200709_141754/meta.yml", "w") as f:
    f.write("serials:\n" + "".join(f"- '{s}'\n" for s in serials) +
            f"extrinsics: {calib_id}\nnum_frames: 72\nmano_sides:\n- right\n"
            "mano_calib: 20200709-subject-01\nycb_ids:\n- 2\n")
truth["dexycb"] = cams

# HO3D v3: calibration/<SEQ>/calibration/ with cam_orders.txt, trans_<i>.txt (4x4
# camera -> common), cam_<i>_intrinsics.txt. The files with index i belong to camera
# folder <SEQ><order[i]> (HO3D's multi-camera viewer); real orders are permutations.
seq = "ABF1"
folder = f"ho3d/calibration/{seq}/calibration"
os.makedirs(folder, exist_ok=True)
order = [1, 3, 2, 4, 0]
with open(f"{folder}/cam_orders.txt", "w") as f:
    f.write(" ".join(str(i) for i in order) + "\n")
cams = []
for i, cam in enumerate(order):
    k = intrinsics()
    with open(f"{folder}/cam_{i}_intrinsics.txt", "w") as f:
        f.write(f"fx:{k['fx']!r}, fy:{k['fy']!r}, ppx:{k['ppx']!r}, ppy:{k['ppy']!r}\n")
    common_from_cam = random_pose()
    np.savetxt(f"{folder}/trans_{i}.txt", common_from_cam, fmt="%.17g")
    cams.append(dict(name=f"{seq}{cam}", params=[k["fx"], k["fy"], k["ppx"], k["ppy"]],
                     width=640, height=480,
                     cam_from_world=np.linalg.inv(common_from_cam)[:3].reshape(-1).tolist()))
truth["ho3d"] = cams

# OakInk-Image: per frame and camera a pickle with cam_intr (3x3) and cam_extr (4x4
# world -> camera), among other annotations.
folder = "oakink/image/anno/general_info"
os.makedirs(folder, exist_ok=True)
cams = []
cam_serials = ["north_east", "south_east", "north_west", "south_west"]
for cam in cam_serials:
    k = intrinsics()
    k_matrix = np.array([[k["fx"], 0, k["ppx"]], [0, k["fy"], k["ppy"]], [0, 0, 1]],
                        dtype=np.float32)
    cam_from_world = random_pose().astype(np.float32)
    for frame in (12, 13):
        anno = dict(cam_intr=k_matrix, cam_extr=cam_from_world,
                    hand_anno=dict(hand_tsl=np.zeros(3, np.float32),
                                   hand_shape=np.zeros(10, np.float32),
                                   hand_pose=np.tile(np.array([0, 0, 0, 1], np.float32),
                                                     (16, 1))),
                    hand_j=np.zeros((21, 3), np.float32))
        name = f"A01001_0001_0000__2021-09-26-19-59-58__0__{frame:05d}__{cam}.pkl"
        with open(f"{folder}/{name}", "wb") as f:
            pickle.dump(anno, f, protocol=4)
    cams.append(dict(name=cam,
                     params=[float(k_matrix[0, 0]), float(k_matrix[1, 1]),
                             float(k_matrix[0, 2]), float(k_matrix[1, 2])],
                     width=848, height=480,
                     cam_from_world=cam_from_world[:3].astype(np.float64).reshape(-1).tolist()))
truth["oakink"] = sorted(cams, key=lambda c: c["name"])  # readers sort by file name

with open("truth.json", "w") as f:
    json.dump(truth, f, indent=1)
