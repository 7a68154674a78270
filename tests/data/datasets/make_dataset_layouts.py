#!/usr/bin/python3
"""Writes a synthetic native capture (`handlabel synth`) in the on-disk layout of DexYCB,
HO3D v3 or OakInk-Image, with the conventions the official loaders read (dex-ycb-toolkit,
the HO3D repository's scripts, OakInk's oikit), plus expected.json: what a correct
reader must find (ground truth in the layout's world, cameras) and the 2D keypoints the
toolkit itself computes from the written files.

Only for making test fixtures; needs Debian's python3-numpy, python3-torch (OakInk's
torch-tensor pickles) and python3-pil (JPEG/PNG files):

  /usr/bin/python3 make_dataset_layouts.py --capture NATIVE --dataset ho3d --out DIR \
      [--seed 7]

What each layout holds (docs/labeling-jobs.md, "Datasets in place"):
  dexycb  calibration/intrinsics/<serial>_640x480.yml and an extra <serial>_1280x720.yml
          (other values: a reader must choose 640x480 as the toolkit does),
          calibration/extrinsics_<id>/extrinsics.yml (camera -> master 3x4 per serial,
          `master`, and an `apriltag` entry), <subject>/<sequence>/meta.yml,
          <serial>/color_%06d.jpg and labels_%06d.npz (seg: 0 background, 255 hand,
          YCB id per object pixel; joint_3d [1,21,3] camera frame; joint_2d [1,21,2];
          pose_m [1,51]). One keypoint of one view is (-1, -1): the toolkit's
          "unlabelled". World = the master camera's frame.
  ho3d    two sequences from the same capture: ABF1 with cam_orders 1 3 2 4 0 (one line)
          and GPMF1 with a random permutation (np.savetxt, one per line); files of
          index i (trans_<i>.txt camera -> common 4x4, cam_<i>_intrinsics.txt) belong to
          camera folder <SEQ><cams_order[i]>; <SEQ><c>/rgb/<fid>.jpg, meta/<fid>.pkl
          (handJoints3D in that camera's OpenGL frame, MANO order + tips; camMat; ...)
          and seg/<fid>.png (blue hand, green object). World = a random common frame.
  oakink  image/anno/general_info/<seq>__<ts>__<sbj>__<frame>__<cam>.pkl with torch
          tensors pickled by plain pickle (torch.storage._load_from_bytes: legacy
          torch.save bytes; camera 3's in the zip form, its cam_extr a strided view),
          anno/hand_j and hand_v (numpy, camera frame), images
          stream_release_v2/<seq>/<ts>/<stream>_<frame>.png. World = a random frame.
Beside ho3d and oakink: detections/<frame id>.json, the capture's simulated detections
in the native format with the layout's camera names (the label job's interim 2D
source, evidence.detections).
"""
import argparse
import io
import json
import os
import pickle
import shutil
from collections import OrderedDict

import numpy as np
from PIL import Image

# SNAP keypoint k is MANO (+ tips) keypoint SNAP_FROM_NATIVE[k] (hand/hand_model.h).
SNAP_FROM_NATIVE = [0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12, 19, 7, 8, 9, 20]
GL_FROM_CV = np.diag([1.0, -1.0, -1.0])  # OpenGL camera axes from OpenCV's


def read_json(path):
    with open(path) as f:
        return json.load(f)


def quat_matrix(xyzw):
    x, y, z, w = xyzw
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def random_rigid(rng):
    """A 4x4 rigid transform (rotation from a random unit quaternion)."""
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    t = np.eye(4)
    t[:3, :3] = quat_matrix(q)
    t[:3, 3] = rng.uniform(-0.5, 0.5, size=3)
    return t


class Capture:
    """The parts of a native capture (docs/capture-format.md) the layouts need."""

    def __init__(self, path):
        self.path = path
        self.manifest = read_json(os.path.join(path, "capture.json"))
        rig = read_json(os.path.join(path, self.manifest["rig"]))
        self.cameras = []
        for c in rig["cameras"]:
            if c["model"] != "PINHOLE":
                raise SystemExit(f"camera {c['name']}: the datasets use pinhole cameras")
            fx, fy, cx, cy = c["params"]
            pose = np.eye(4)
            pose[:3, :3] = quat_matrix(c["cam_from_world"]["rotation_xyzw"])
            pose[:3, 3] = c["cam_from_world"]["translation"]
            self.cameras.append(dict(name=c["name"], width=c["width"], height=c["height"],
                                     K=np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]]),
                                     cam_from_world=pose))
        self.frames = self.manifest["frames"]

    def file(self, kind, frame, camera=""):
        pattern = self.manifest["files"][kind]
        return os.path.join(self.path, pattern.replace("{camera}", camera)
                            .replace("{frame}", frame))

    def truth(self, frame):
        gt = read_json(self.file("ground_truth", frame))
        return np.array(gt["keypoints3d"]), gt

    def gray(self, kind, frame, camera):
        return np.array(Image.open(self.file(kind, frame, camera)))

    def views(self, kind, frame):
        return {v["camera"]: v for v in read_json(self.file(kind, frame))["views"]}


def transform(t, points):
    return points @ t[:3, :3].T + t[:3, 3]


def project(K, points_cam):
    """The toolkits' pinhole projection: K X, divided by z."""
    uvw = points_cam @ K.T
    return uvw[:, :2] / uvw[:, 2:]


def camera_record(name, native, K, cam_from_world, width, height):
    return dict(name=name, native_camera=native, width=width, height=height,
                params=[K[0, 0], K[1, 1], K[0, 2], K[1, 2]],
                cam_from_world=cam_from_world[:3].reshape(-1).tolist())


def write_detections(capture, frame, out_path, names, frame_id):
    """The native detections of `frame` with cameras renamed (native -> layout), as
    the detections of the layout's frame `frame_id` (readers refuse a file of another
    frame)."""
    record = read_json(capture.file("detections", frame))
    record["frame"] = frame_id
    for view in record["views"]:
        view["camera"] = names[view["camera"]]
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w") as f:
        json.dump(record, f)


# ------------------------------------------------------------------------------ DexYCB

DEXYCB_SERIALS = ["836212060125", "839512060362", "840412060917", "841412060263",
                  "932122060857", "932122060861", "932122061900", "932122062010"]


def write_yaml_intrinsics(path, K):
    with open(path, "w") as f:
        f.write("color:\n")
        for key, v in (("fx", K[0, 0]), ("fy", K[1, 1]), ("ppx", K[0, 2]), ("ppy", K[1, 2])):
            f.write(f"  {key}: {float(v)!r}\n")
        f.write("depth:\n  fx: 380.0\n  fy: 380.0\n  ppx: 320.0\n  ppy: 240.0\n")


def make_dexycb(capture, out, rng):
    cams = capture.cameras
    if len(cams) > len(DEXYCB_SERIALS):
        raise SystemExit("at most 8 cameras for DexYCB")
    serials = DEXYCB_SERIALS[:len(cams)]
    master = 2 % len(cams)  # not the first serial: the common frame is the master's
    world_from_native = cams[master]["cam_from_world"]
    calib_id = "20200709-subject-01"
    subject, sequence = "20200709-subject-01", "20200709_141754"
    seq_dir = os.path.join(out, subject, sequence)
    os.makedirs(os.path.join(out, "calibration", "intrinsics"), exist_ok=True)
    os.makedirs(os.path.join(out, "calibration", f"extrinsics_{calib_id}"), exist_ok=True)
    lines = []
    records = []
    for serial, cam in zip(serials, cams):
        if (cam["width"], cam["height"]) != (640, 480):
            raise SystemExit("DexYCB cameras are 640x480")
        intr = os.path.join(out, "calibration", "intrinsics", serial)
        write_yaml_intrinsics(intr + "_640x480.yml", cam["K"])
        # The 1280x720 colour stream of the same camera: other values, first in name order.
        write_yaml_intrinsics(intr + "_1280x720.yml", cam["K"] * np.array([[2, 1, 2], [1, 1.5, 1.5], [1, 1, 1]]))
        cam_from_common = cam["cam_from_world"] @ np.linalg.inv(world_from_native)
        common_from_cam = np.linalg.inv(cam_from_common)
        values = ", ".join(repr(float(v)) for v in common_from_cam[:3].reshape(-1))
        lines.append(f"  '{serial}': [{values}]\n")
        records.append(camera_record(serial, cam["name"], cam["K"], cam_from_common, 640, 480))
    tag = random_rigid(rng)  # the calibration tag's pose in the common frame
    lines.append("  apriltag: [" + ", ".join(repr(float(v)) for v in tag[:3].reshape(-1)) + "]\n")
    with open(os.path.join(out, "calibration", f"extrinsics_{calib_id}", "extrinsics.yml"), "w") as f:
        f.write("extrinsics:\n" + "".join(lines) + f"master: '{serials[master]}'\n")
    os.makedirs(seq_dir, exist_ok=True)
    ycb_ids = [2, 5, 10, 14]
    with open(os.path.join(seq_dir, "meta.yml"), "w") as f:
        f.write("serials:\n" + "".join(f"- '{s}'\n" for s in serials) +
                f"extrinsics: {calib_id}\nnum_frames: {len(capture.frames)}\n"
                f"mano_sides:\n- right\nmano_calib: {subject}\n"
                "ycb_ids:\n" + "".join(f"- {i}\n" for i in ycb_ids) + "ycb_grasp_ind: 0\n")
    frames = []
    unlabelled = (1 % len(cams), 8)  # (view, keypoint) written as (-1, -1) in frame 0
    for f_index, frame in enumerate(capture.frames):
        keypoints, gt = capture.truth(frame)
        truth_views = capture.views("keypoints", frame)
        fid = f"{f_index:06d}"
        views = []
        for v, (serial, cam) in enumerate(zip(serials, cams)):
            cam_dir = os.path.join(seq_dir, serial)
            os.makedirs(cam_dir, exist_ok=True)
            rgb = Image.open(capture.file("image", frame, cam["name"])).convert("RGB")
            rgb.save(os.path.join(cam_dir, f"color_{fid}.jpg"), quality=95)
            hand = capture.gray("mask", frame, cam["name"]) > 127
            objects = capture.gray("object_mask", frame, cam["name"])
            seg = np.zeros(hand.shape, np.uint8)
            for k in range(1, int(objects.max()) + 1):
                seg[objects == k] = ycb_ids[(k - 1) % len(ycb_ids)]
            seg[hand] = 255
            in_cam = transform(cam["cam_from_world"], keypoints)
            joint_3d = in_cam.astype(np.float32)
            # The toolkit's 2D: the stored joint_3d projected with the 640x480 intrinsics.
            joint_2d = project(cam["K"], joint_3d.astype(np.float64)).astype(np.float32)
            labelled = [True] * 21
            has_hand = truth_views[cam["name"]]["status"] != "out_of_frame"
            if not has_hand:  # DexYCB: -1 everywhere in a view without the hand
                joint_3d[:] = -1
                joint_2d[:] = -1
                labelled = [False] * 21
            elif f_index == 0 and v == unlabelled[0]:
                joint_2d[unlabelled[1]] = -1
                labelled[unlabelled[1]] = False
            pose_m = np.concatenate([gt["global_orient"], gt["hand_pose"], gt["transl"]])
            np.savez_compressed(os.path.join(cam_dir, f"labels_{fid}.npz"), seg=seg,
                                joint_3d=joint_3d[None], joint_2d=joint_2d[None],
                                pose_y=np.zeros((len(ycb_ids), 3, 4), np.float32),
                                pose_m=pose_m.astype(np.float32)[None])
            views.append(dict(camera=serial, uv=project(cam["K"], in_cam).tolist(),
                              labelled=labelled, has_hand=has_hand,
                              toolkit_uv=joint_2d.astype(np.float64).tolist()))
        frames.append(dict(id=fid, native_frame=frame,
                           keypoints3d=transform(world_from_native, keypoints).tolist(),
                           views=views))
    return dict(dataset="dexycb", path=seq_dir, cameras=records, frames=frames,
                master=serials[master], apriltag=tag[:3].reshape(-1).tolist())


# ------------------------------------------------------------------------------ HO3D

def write_ho3d_sequence(capture, out, seq, order, order_as_column, rng):
    """One HO3D v3 sequence of all capture cameras; `order` is cam_orders.txt."""
    cams = capture.cameras
    common_from_native = random_rigid(rng)
    calib = os.path.join(out, "calibration", seq, "calibration")
    os.makedirs(calib, exist_ok=True)
    if order_as_column:
        np.savetxt(os.path.join(calib, "cam_orders.txt"), np.array(order), fmt="%d")
    else:
        with open(os.path.join(calib, "cam_orders.txt"), "w") as f:
            f.write(" ".join(str(c) for c in order) + "\n")
    records = []
    for i, c in enumerate(order):  # files of index i belong to camera folder <SEQ><c>
        cam = cams[c]
        K = cam["K"]
        with open(os.path.join(calib, f"cam_{i}_intrinsics.txt"), "w") as f:
            f.write(f"fx:{K[0, 0]!r}, fy:{K[1, 1]!r}, ppx:{K[0, 2]!r}, ppy:{K[1, 2]!r}\n")
        common_from_cam = common_from_native @ np.linalg.inv(cam["cam_from_world"])
        np.savetxt(os.path.join(calib, f"trans_{i}.txt"), common_from_cam, fmt="%.17g")
        records.append(camera_record(f"{seq}{c}", cam["name"], K,
                                     np.linalg.inv(common_from_cam), 640, 480))
    frames = []
    for f_index, frame in enumerate(capture.frames):
        keypoints, gt = capture.truth(frame)
        fid = f"{f_index:04d}"
        views = []
        for c, cam in enumerate(cams):
            cam_dir = os.path.join(out, "train", f"{seq}{c}")
            for sub in ("rgb", "meta", "seg"):
                os.makedirs(os.path.join(cam_dir, sub), exist_ok=True)
            Image.open(capture.file("image", frame, cam["name"])).convert("RGB").save(
                os.path.join(cam_dir, "rgb", fid + ".jpg"), quality=95)
            hand = capture.gray("mask", frame, cam["name"]) > 127
            objects = capture.gray("object_mask", frame, cam["name"]) > 0
            seg = np.zeros(hand.shape + (3,), np.uint8)  # RGB: blue hand, green object
            seg[..., 2][hand] = 255
            seg[..., 1][objects] = 255
            Image.fromarray(seg).save(os.path.join(cam_dir, "seg", fid + ".png"))
            in_cam = transform(cam["cam_from_world"], keypoints)
            mano_order = np.zeros((21, 3))
            mano_order[SNAP_FROM_NATIVE] = in_cam
            joints_gl = (mano_order @ GL_FROM_CV.T).astype(np.float32)
            meta = dict(handJoints3D=joints_gl, camMat=cam["K"].astype(np.float32),
                        handPose=np.concatenate([gt["global_orient"], gt["hand_pose"]]).astype(np.float32),
                        handTrans=np.array(gt["transl"], np.float32),
                        handBeta=np.array(gt["betas"], np.float32),
                        objName="006_mustard_bottle", objLabel=5,
                        objRot=np.zeros((3, 1), np.float32), objTrans=np.zeros(3, np.float32))
            with open(os.path.join(cam_dir, "meta", fid + ".pkl"), "wb") as f:
                pickle.dump(meta, f, protocol=2)
            # The toolkit's projectPoints: OpenGL -> OpenCV axes, K, divide by z.
            uv_mano = project(meta["camMat"].astype(np.float64),
                              joints_gl.astype(np.float64) @ GL_FROM_CV.T)
            views.append(dict(camera=f"{seq}{c}", uv=project(K, in_cam).tolist(),
                              toolkit_uv=uv_mano[SNAP_FROM_NATIVE].tolist()))
        write_detections(capture, frame, os.path.join(out, "detections", seq, fid + ".json"),
                         {cam["name"]: f"{seq}{c}" for c, cam in enumerate(cams)},
                         f"{seq}/{fid}")
        frames.append(dict(id=f"{seq}/{fid}", native_frame=frame,
                           keypoints3d=transform(common_from_native, keypoints).tolist(),
                           views=views))
    return dict(name=seq, path=os.path.join(out, "train", seq), order=list(order),
                cameras=records, frames=frames)


def make_ho3d(capture, out, rng):
    if len(capture.cameras) != 5:
        raise SystemExit("HO3D sequences have 5 cameras")
    random_order = [int(c) for c in rng.permutation(5)]
    return dict(dataset="ho3d", sequences=[
        write_ho3d_sequence(capture, out, "ABF1", [1, 3, 2, 4, 0], False, rng),
        write_ho3d_sequence(capture, out, "GPMF1", random_order, True, rng)])


# ------------------------------------------------------------------------------ OakInk

OAKINK_STREAMS = ["north_east_color", "south_east_color", "north_west_color",
                  "south_west_color"]


class _ZipSavedStorage:
    """Pickles as torch.storage._load_from_bytes(<zip torch.save of the storage>): the
    zip form of a storage inside a plain pickle."""

    def __init__(self, storage):
        self.storage = storage

    def __reduce__(self):
        import torch
        buffer = io.BytesIO()
        torch.save(self.storage, buffer, _use_new_zipfile_serialization=True)
        return (torch.storage._load_from_bytes, (buffer.getvalue(),))


class _ZipTensor:
    """Pickles like a torch tensor (torch._utils._rebuild_tensor_v2) whose storage is in
    the zip form."""

    def __init__(self, tensor):
        self.tensor = tensor

    def __reduce__(self):
        import torch
        t = self.tensor
        return (torch._utils._rebuild_tensor_v2,
                (_ZipSavedStorage(t.storage()), t.storage_offset(), tuple(t.size()),
                 t.stride(), False, OrderedDict()))


def make_oakink(capture, out, rng):
    import torch
    cams = capture.cameras
    if len(cams) != 4:
        raise SystemExit("OakInk-Image has 4 cameras")
    world_from_native = random_rigid(rng)
    image_dir = os.path.join(out, "image")
    info_dir = os.path.join(image_dir, "anno", "general_info")
    for d in ("general_info", "hand_j", "hand_v"):
        os.makedirs(os.path.join(image_dir, "anno", d), exist_ok=True)
    seq, ts, sbj = "A01001_0001_0000", "2021-09-26-19-59-58", "0"
    records = {}
    frames = []
    for f_index, frame in enumerate(capture.frames):
        keypoints, gt = capture.truth(frame)
        number = f"{12 + f_index:05d}"
        group = f"{seq}__{ts}__{sbj}__{number}"
        views = []
        for c, cam in enumerate(cams):
            cam_from_oak = cam["cam_from_world"] @ np.linalg.inv(world_from_native)
            intr = torch.tensor(cam["K"], dtype=torch.float32)
            extr = torch.tensor(cam_from_oak, dtype=torch.float32)
            zip_form = c == 3
            if zip_form:  # a strided view: the transpose of a contiguous transpose
                extr = _ZipTensor(extr.t().contiguous().t())
                intr = _ZipTensor(intr)
            anno = dict(cam_intr=intr, cam_extr=extr,
                        hand_anno=dict(hand_tsl=torch.tensor(gt["transl"], dtype=torch.float32),
                                       hand_shape=torch.tensor(gt["betas"], dtype=torch.float32),
                                       hand_pose=torch.zeros(16, 4)),
                        obj_anno=dict(obj_transf=torch.eye(4)))
            name = f"{group}__{c}.pkl"
            with open(os.path.join(info_dir, name), "wb") as f:
                pickle.dump(anno, f, protocol=4)
            # What oikit computes from the files: hand_j (camera frame) projected with
            # cam_intr.numpy().
            with open(os.path.join(info_dir, name), "rb") as f:
                loaded = pickle.load(f)
            K32 = loaded["cam_intr"].numpy().astype(np.float64)
            extr32 = loaded["cam_extr"].numpy().astype(np.float64)
            hand_j = transform(extr32, transform(world_from_native, keypoints)).astype(np.float32)
            with open(os.path.join(image_dir, "anno", "hand_j", name), "wb") as f:
                pickle.dump(hand_j, f, protocol=4)
            vertices = np.array(gt["vertices"])
            hand_v = transform(extr32, transform(world_from_native, vertices)).astype(np.float32)
            with open(os.path.join(image_dir, "anno", "hand_v", name), "wb") as f:
                pickle.dump(hand_v, f, protocol=4)
            stream_dir = os.path.join(image_dir, "stream_release_v2", seq, ts)
            os.makedirs(stream_dir, exist_ok=True)
            shutil.copyfile(capture.file("image", frame, cam["name"]),
                            os.path.join(stream_dir, f"{OAKINK_STREAMS[c]}_{number}.png"))
            records[str(c)] = camera_record(str(c), cam["name"], K32, extr32, 848, 480)
            views.append(dict(camera=str(c),
                              uv=project(cam["K"], transform(cam["cam_from_world"], keypoints)).tolist(),
                              toolkit_uv=project(K32, hand_j.astype(np.float64)).tolist()))
        write_detections(capture, frame, os.path.join(out, "detections", group + ".json"),
                         {cam["name"]: str(c) for c, cam in enumerate(cams)}, group)
        frames.append(dict(id=group, native_frame=frame,
                           keypoints3d=transform(world_from_native, keypoints).tolist(),
                           vertices_first=transform(world_from_native,
                                                    np.array(gt["vertices"][:5])).tolist(),
                           views=views))
    return dict(dataset="oakink", path=image_dir, cameras=[records[k] for k in sorted(records)],
                frames=frames)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--capture", required=True, help="native capture folder")
    parser.add_argument("--dataset", required=True, choices=["dexycb", "ho3d", "oakink"])
    parser.add_argument("--out", required=True, help="output folder (created)")
    parser.add_argument("--seed", type=int, default=7, help="random frames and orders")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    capture = Capture(args.capture)
    os.makedirs(args.out, exist_ok=True)
    make = dict(dexycb=make_dexycb, ho3d=make_ho3d, oakink=make_oakink)[args.dataset]
    expected = make(capture, args.out, rng)
    expected["seed"] = args.seed
    expected["capture"] = os.path.abspath(args.capture)
    with open(os.path.join(args.out, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)


if __name__ == "__main__":
    main()
