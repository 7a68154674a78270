#!/usr/bin/python3
"""Writes the seed corpora of the parser fuzz targets (docs/fuzzing.md):
corpus/rig_json/, corpus/capture_json/ (first byte picks the reader), corpus/colmap_model/
(first byte: even text, odd binary; files joined with "@@@@"), corpus/torch_archive/
(copies of tests/data/npy/state_dict.pt and a truncated one) and corpus/job_yaml/ (the
shipped jobs and small variants). Small valid inputs keep the fuzzer fast.

Run from anywhere:  /usr/bin/python3 fuzz/make_parser_corpora.py
"""
import json
import os
import shutil
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def write(folder, name, data):
    path = os.path.join(HERE, "corpus", folder)
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def camera(name, model, params, width=640, height=480, t=(0.1, -0.2, 0.5)):
    return {"name": name, "model": model, "width": width, "height": height,
            "params": params,
            "cam_from_world": {"rotation_xyzw": [0, 0, 0, 1], "translation": list(t)}}


def rig_seeds():
    pin = camera("cam0", "PINHOLE", [500, 500, 320, 240])
    cv = camera("cam1", "OPENCV", [600, 610, 330, 250, 0.1, -0.05, 0.001, 0.002])
    fish = camera("cam2", "OPENCV_FISHEYE", [300, 300, 320, 240, 0.1, 0.01, 0, 0])
    simple = camera("cam3", "SIMPLE_RADIAL", [550, 320, 240, 0.02])
    full = camera("cam4", "FULL_OPENCV", [600, 600, 320, 240] + [0.01] * 8)
    write("rig_json", "one_pinhole.json",
          json.dumps({"format": "handlabel-rig", "version": 1, "cameras": [pin]}))
    write("rig_json", "models.json",
          json.dumps({"format": "handlabel-rig", "version": 1, "world": "camera:cam0",
                      "cameras": [pin, cv, fish, simple, full]}, indent=1))


def capture_seeds():
    manifest = {"format": "handlabel-capture", "version": 1, "rig": "rig.json",
                "cameras": ["cam0", "cam1"], "frames": ["000000", "000001"],
                "files": {"image": "images/{camera}/{frame}.png"},
                "depth_unit_m": 0.0001, "world": "table", "hand_side": "right",
                "generator": {"seed": 3}}
    write("capture_json", "manifest.json", b"\x00" + json.dumps(manifest).encode())
    kp = [[100.5 + k, 200.25 - k] for k in range(21)]
    kp[3] = [None, None]
    views = {"frame": "000000", "views": [
        {"camera": "cam0", "keypoints": kp, "confidence": [0.9] * 20 + [0.0]},
        {"camera": "cam1", "keypoints": kp, "visibility": [2] * 21, "status": "visible",
         "hand_pixels": 5321}]}
    write("capture_json", "keypoints.json", b"\x01" + json.dumps(views).encode())
    gt = {"frame": "000000", "hand_model": "open_hand_right", "side": "right",
          "pose_kind": "grasp", "global_orient": [0.1, 0.2, 0.3],
          "hand_pose": [0.01 * i for i in range(45)], "betas": [0.0] * 10,
          "transl": [0.0, 0.1, 0.5], "keypoints3d": [[0.01 * k, 0, 0.5] for k in range(21)],
          "joints3d": [[0.01 * k, 0, 0.5] for k in range(16)],
          "vertices": [[0, 0, 0.5], [0.01, 0, 0.5]],
          "objects": [{"kind": "box", "size": [0.05, 0.03, 0.07],
                       "world_from_object": {"rotation_xyzw": [0, 0, 0, 1],
                                             "translation": [0, 0, 0.6]}}]}
    write("capture_json", "ground_truth.json", b"\x02" + json.dumps(gt).encode())


def colmap_seeds():
    cameras = ("# Camera list\n1 PINHOLE 640 480 500 500 320 240\n"
               "2 OPENCV 640 480 600 600 320 240 0.1 -0.05 0.001 0.002\n")
    images = ("# Image list\n1 1 0 0 0 0.1 0.2 0.5 1 cam0\n100 200 -1\n"
              "2 0.7071068 0 0.7071068 0 -0.5 0 0.5 2 cam1\n\n")
    points = "# 3D points\n1 0.1 0.2 1.5 255 128 0 0.5 1 0 2 0\n"
    write("colmap_model", "text", b"\x00" + "@@@@".join([cameras, images, points]).encode())
    cams = struct.pack("<Q", 1) + struct.pack("<IiQQ", 1, 1, 640, 480) + struct.pack(
        "<4d", 500, 500, 320, 240)
    ims = struct.pack("<Q", 1) + struct.pack("<I4d3dI", 1, 1, 0, 0, 0, 0.1, 0.2, 0.5, 1)
    ims += b"cam0\x00" + struct.pack("<Q", 1) + struct.pack("<2dq", 100, 200, -1)
    pts = struct.pack("<Q", 1) + struct.pack("<Q3d3Bd", 1, 0.1, 0.2, 1.5, 255, 128, 0, 0.5)
    pts += struct.pack("<Q", 1) + struct.pack("<II", 1, 0)
    write("colmap_model", "binary", b"\x01" + b"@@@@".join([cams, ims, pts]))


def torch_seeds():
    src = os.path.join(ROOT, "tests", "data", "npy", "state_dict.pt")
    data = open(src, "rb").read()
    write("torch_archive", "state_dict.pt", data)
    write("torch_archive", "state_dict_truncated.pt", data[: len(data) // 2])


def job_seeds():
    for name in ("demo.yaml", "dexycb.yaml", "fit_baseline.yaml"):
        shutil.copy(os.path.join(ROOT, "jobs", name),
                    os.path.join(HERE, "corpus", "job_yaml", name))
    write("job_yaml", "minimal.yaml",
          "name: m\nseed: 1\ninput: {format: native, path: c, frames: \"0:4\"}\n"
          "output: {dir: out, meshes: [ply, obj]}\n")


if __name__ == "__main__":
    os.makedirs(os.path.join(HERE, "corpus", "job_yaml"), exist_ok=True)
    rig_seeds()
    capture_seeds()
    colmap_seeds()
    torch_seeds()
    job_seeds()
