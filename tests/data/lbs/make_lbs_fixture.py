#!/usr/bin/python3
"""Writes lbs_fixture.json: a small random MANO-structured model, parameter sets and
the MANO forward pass computed here with NumPy, independently of the C++ code.

Run with /usr/bin/python3 (numpy only):  /usr/bin/python3 make_lbs_fixture.py
Inputs are rounded to few digits (small file); outputs are written at full precision
(json writes repr floats, which round-trip exactly).
"""
import json
import os

import numpy as np

NUM_VERTS = 48
NUM_BETAS = 10
PARENTS = [-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14]
SNAP_FROM_NATIVE = [0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12, 19, 7, 8, 9, 20]


def rodrigues(w):
    """Rotation matrix from axis-angle via the matrix exponential series of [w]x,
    summed to convergence (deliberately not the closed form used in C++)."""
    k = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    r = np.eye(3)
    term = np.eye(3)
    for n in range(1, 60):
        term = term @ k / n
        r = r + term
    return r


def lbs(model, global_orient, hand_pose, betas, transl):
    v = model["v_template"]
    nv = v.shape[0]
    shapedirs = model["shapedirs"].reshape(nv, 3, -1)
    posedirs = model["posedirs"].reshape(nv, 3, 135)
    v_shaped = v + np.einsum("vcs,s->vc", shapedirs, betas)
    joints = model["J_regressor"] @ v_shaped
    full_pose = np.concatenate([global_orient, hand_pose]).reshape(16, 3)
    rots = np.stack([rodrigues(w) for w in full_pose])
    feature = (rots[1:] - np.eye(3)).reshape(-1)
    v_posed = v_shaped + np.einsum("vck,k->vc", posedirs, feature)
    # 4x4 chain, smplx style: G_j = G_parent [R_j | J_j - J_parent], root [R_0 | J_0].
    world = []
    for j in range(16):
        local = np.eye(4)
        local[:3, :3] = rots[j]
        p = PARENTS[j]
        local[:3, 3] = joints[j] - (joints[p] if p >= 0 else 0.0)
        world.append(local if p < 0 else world[p] @ local)
    world = np.stack(world)
    posed_joints = world[:, :3, 3].copy()
    rel = world.copy()
    for j in range(16):
        rel[j, :3, 3] -= world[j, :3, :3] @ joints[j]
    blend = np.einsum("vj,jab->vab", model["weights"], rel)
    hom = np.concatenate([v_posed, np.ones((nv, 1))], axis=1)
    verts = np.einsum("vab,vb->va", blend, hom)[:, :3] + transl
    posed_joints = posed_joints + transl
    with_tips = np.concatenate([posed_joints, verts[model["tip_vertex_ids"]]])
    keypoints = with_tips[SNAP_FROM_NATIVE]
    return verts, posed_joints, keypoints


def make_model(rng):
    nv = NUM_VERTS
    m = {}
    m["v_template"] = np.round(rng.uniform(-0.08, 0.08, (nv, 3)), 4)
    faces = []
    while len(faces) < 80:
        tri = rng.choice(nv, 3, replace=False)
        faces.append(tri.tolist())
    m["faces"] = np.array(faces)
    m["shapedirs"] = np.round(rng.normal(0, 0.01, (3 * nv, NUM_BETAS)), 4)
    m["posedirs"] = np.round(rng.normal(0, 0.01, (3 * nv, 135)), 4)
    reg = np.zeros((16, nv))
    for j in range(16):
        ids = rng.choice(nv, 5, replace=False)
        w = rng.uniform(0.1, 1.0, 5)
        reg[j, ids] = w / w.sum()  # rows sum to 1, as MANO's
    m["J_regressor"] = reg
    weights = np.zeros((nv, 16))
    for v in range(nv):
        count = rng.integers(1, 5)
        ids = rng.choice(16, count, replace=False)
        w = rng.uniform(0.1, 1.0, count)
        weights[v, ids] = w / w.sum()
    m["weights"] = weights
    m["tip_vertex_ids"] = rng.choice(nv, 5, replace=False)
    q, _ = np.linalg.qr(rng.normal(size=(45, 45)))
    m["hands_components"] = np.round(q * rng.uniform(0.2, 1.5, (45, 1)), 5)
    m["hands_mean"] = np.round(rng.normal(0, 0.2, 45), 4)
    return m


def tolist(a):
    return np.asarray(a).tolist()


def main():
    rng = np.random.default_rng(20261122)
    model = make_model(rng)
    cases = []
    specs = [
        ("rest", 0.0, 0.0, 0.0, 0.0),
        ("shape_only", 0.0, 0.0, 1.0, 0.0),
        ("small_pose", 0.2, 0.3, 1.0, 0.1),
        ("large_pose", 2.5, 1.5, 2.0, 0.5),
        ("mixed_zero_joints", 1.0, 1.0, 1.0, 0.3),
    ]
    for name, orient_scale, pose_scale, beta_scale, transl_scale in specs:
        orient = rng.normal(0, orient_scale / 1.7, 3) if orient_scale else np.zeros(3)
        pose = rng.normal(0, pose_scale / 1.7, 45) if pose_scale else np.zeros(45)
        if name == "mixed_zero_joints":
            pose[3:9] = 0.0  # some joints exactly at identity
            pose[30:33] = [1e-9, -2e-9, 0.5e-9]
        betas = rng.normal(0, beta_scale, NUM_BETAS)
        transl = rng.normal(0, transl_scale, 3)
        verts, joints, kps = lbs(model, orient, pose, betas, transl)
        cases.append(dict(name=name, global_orient=tolist(orient), hand_pose=tolist(pose),
                          betas=tolist(betas), transl=tolist(transl),
                          vertices=tolist(verts), joints=tolist(joints),
                          keypoints=tolist(kps)))
    pca_cases = []
    for ncomps, flat in [(6, False), (12, True), (45, False)]:
        coeffs = rng.normal(0, 0.8, ncomps)
        pose = coeffs @ model["hands_components"][:ncomps]
        if not flat:
            pose = pose + model["hands_mean"]
        orient = rng.normal(0, 0.5, 3)
        betas = rng.normal(0, 1.0, NUM_BETAS)
        transl = rng.normal(0, 0.2, 3)
        verts, joints, kps = lbs(model, orient, pose, betas, transl)
        pca_cases.append(dict(coeffs=tolist(coeffs), flat_hand_mean=flat,
                              hand_pose=tolist(pose), global_orient=tolist(orient),
                              betas=tolist(betas), transl=tolist(transl),
                              vertices=tolist(verts), keypoints=tolist(kps)))
    out = dict(
        comment="Generated by make_lbs_fixture.py; random model, not MANO data.",
        model={k: tolist(v) for k, v in model.items()},
        parents=PARENTS,
        cases=cases,
        pca_cases=pca_cases)
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "lbs_fixture.json")
    with open(path, "w") as f:
        json.dump(out, f, separators=(",", ":"))
    print("wrote", path, os.path.getsize(path), "bytes")


if __name__ == "__main__":
    main()
