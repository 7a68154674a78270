#!/usr/bin/python3
"""Independent reference forward pass of POEM, used only as a test oracle.

Written from docs/network.md and the shared architecture notes, with functional torch
ops on a state_dict (no code shared with the C++ side). It
  1. draws random weights with the reference's key names and shapes for a PoemConfig,
  2. writes them with torch.save (the released checkpoint's container) and as a raw
     tensor bundle,
  3. draws a synthetic multi-view batch (random crops, cameras on a ring),
  4. runs the forward pass with the deterministic point selection rule and writes
     inputs and every intermediate the C++ test compares.

Usage: poem_oracle.py --config config.json --out DIR [--seed S] [--batch B]
Tensor bundles: NAME.json ({key: {dtype, shape, offset}}) + NAME.bin (little endian).
"""

import argparse
import collections
import json
import math
import os

import torch
import torch.nn.functional as F

J, V = 21, 778
Q = J + V


# ---------------------------------------------------------------- config and weights
def stage_blocks(cfg):
    return [2, 2, 2, 2] if cfg["backbone"] == "resnet18" else [3, 4, 6, 3]


def random_state_dict(cfg, gen):
    sd = collections.OrderedDict()

    def normal(shape, fan_in):
        return torch.randn(shape, generator=gen) / math.sqrt(max(fan_in, 1))

    def conv(name, cin, cout, k, bias):
        sd[name + ".weight"] = normal((cout, cin, k, k), cin * k * k)
        if bias:
            sd[name + ".bias"] = 0.1 * torch.randn(cout, generator=gen)

    def linear(name, cin, cout, bias=True):
        sd[name + ".weight"] = normal((cout, cin), cin)
        if bias:
            sd[name + ".bias"] = 0.1 * torch.randn(cout, generator=gen)

    def bn(name, c, frozen):
        sd[name + ".weight"] = 1 + 0.1 * torch.randn(c, generator=gen)
        sd[name + ".bias"] = 0.1 * torch.randn(c, generator=gen)
        sd[name + ".running_mean"] = 0.1 * torch.randn(c, generator=gen)
        sd[name + ".running_var"] = 0.5 + torch.rand(c, generator=gen)
        if not frozen:
            sd[name + ".num_batches_tracked"] = torch.tensor(7, dtype=torch.int64)

    def mlp(name, cin, hidden, cout):
        linear(name + ".0", cin, hidden)
        linear(name + ".2", hidden, cout)

    w = cfg["backbone_width"]
    E = cfg["embed_dim"]
    T = cfg["transformer_dim"]
    D = cfg["depth_bins"]
    conv("img_backbone.conv1", 3, w, 7, False)
    bn("img_backbone.bn1", w, True)
    inplanes = w
    for s, nblocks in enumerate(stage_blocks(cfg)):
        planes = w << s
        for b in range(nblocks):
            p = "img_backbone.layer%d.%d" % (s + 1, b)
            frozen = b == 0
            stride = 2 if (b == 0 and s > 0) else 1
            conv(p + ".conv1", inplanes, planes, 3, False)
            bn(p + ".bn1", planes, frozen)
            conv(p + ".conv2", planes, planes, 3, False)
            bn(p + ".bn2", planes, frozen)
            if stride != 1 or inplanes != planes:
                conv(p + ".downsample.0", inplanes, planes, 1, False)
                bn(p + ".downsample.1", planes, frozen)
            inplanes = planes
    linear("img_backbone.fc", 8 * w, 1000)
    for dec in ("uv_delayer", "feat_delayer"):
        chans = [(4 * w + 8 * w, 4 * w), (2 * w + 4 * w, 2 * w), (w + 2 * w, w)]
        for i, (cin, cout) in enumerate(chans):
            conv("%s.%d.conv" % (dec, i), cin, cout, 3, True)
            bn("%s.%d.norm" % (dec, i), cout, False)
    conv("uv_out.conv", w, J, 1, True)
    conv("uv_in.conv", J, 2 * w, 1, True)
    bn("uv_in.norm", 2 * w, False)
    conv("feat_in.conv", w, 2 * w, 1, True)
    # Around the reference initialisation (1/21, zero bias) but without exact ties.
    sd["linear_inv_skin.weight"] = 1.0 / J + 0.02 * torch.randn((V, J), generator=gen)
    sd["linear_inv_skin.bias"] = 0.01 * torch.randn(V, generator=gen)
    h = "ptEmb_head."
    mlp(h + "center_shift_layer", Q, Q, 1)
    conv(h + "input_proj", 2 * w, E, 1, True)
    for i in range(cfg["num_decoder_blocks"]):
        mlp(h + "reg_branches.%d" % i, E, E, 3)
        # Small updates, as in a trained model: coordinates stay inside the position
        # range instead of saturating the sigmoid at its edges.
        sd[h + "reg_branches.%d.2.weight" % i] *= 0.02
        sd[h + "reg_branches.%d.2.bias" % i] *= 0.02
    conv(h + "adapt_pos3d", 3 * E // 2, E, 1, True)
    conv(h + "position_encoder.0", 3 * D, 2 * E, 1, True)
    conv(h + "position_encoder.2", 2 * E, E, 1, True)
    sd[h + "reference_embed.weight"] = torch.rand((Q, E), generator=gen)
    mlp(h + "query_embedding", E, E, E)
    for m in ("merge_net_feature", "merge_net_query_feature"):
        mlp(h + m + ".0", E, E, E // 2)
        mlp(h + m + ".1", E // 2, E // 2, E)
    linear(h + "layer_global_feat", 8 * w, E)

    def attention(p, cross):
        linear(p + ".fc1", E, T)
        linear(p + ".fc2", T, E)
        mlp(p + ".fc_delta", 3, T, T)
        mlp(p + ".fc_gamma", T, T, T)
        linear(p + ".w_qs", E if cross else T, T, bias=False)
        linear(p + ".w_ks", T, T, bias=False)
        linear(p + ".w_vs", T, T, bias=False)

    t = h + "transformer."
    attention(t + "feats_self_attn", False)
    for i in range(cfg["num_decoder_blocks"]):
        attention(t + "query_self_attn.%d" % i, False)
        attention(t + "query_feats_cross_attn.%d" % i, True)
    # MANO buffers of the released checkpoint, which the C++ side must ignore.
    sd["mano_layer.th_faces"] = torch.zeros((1538, 3), dtype=torch.int64)
    return sd


# ---------------------------------------------------------------------------- layers
def frozen_bn(x, sd, p):
    scale = sd[p + ".weight"] * (sd[p + ".running_var"] + 1e-5).rsqrt()
    shift = sd[p + ".bias"] - sd[p + ".running_mean"] * scale
    return x * scale.reshape(1, -1, 1, 1) + shift.reshape(1, -1, 1, 1)


def batch_norm(x, sd, p):
    return F.batch_norm(x, sd[p + ".running_mean"], sd[p + ".running_var"],
                        sd[p + ".weight"], sd[p + ".bias"], False, 0.1, 1e-5)


def norm(x, sd, p):
    return batch_norm(x, sd, p) if (p + ".num_batches_tracked") in sd else frozen_bn(x, sd, p)


def conv(x, sd, p, stride=1, padding=0):
    return F.conv2d(x, sd[p + ".weight"], sd.get(p + ".bias"), stride, padding)


def lin(x, sd, p):
    return F.linear(x, sd[p + ".weight"], sd.get(p + ".bias"))


def mlp(x, sd, p):
    return lin(F.relu(lin(x, sd, p + ".0")), sd, p + ".2")


def backbone(x, sd, cfg):
    b = "img_backbone."
    x = F.relu(frozen_bn(conv(x, sd, b + "conv1", 2, 3), sd, b + "bn1"))
    x = F.max_pool2d(x, 3, 2, 1)
    feats = []
    for s, nblocks in enumerate(stage_blocks(cfg)):
        for i in range(nblocks):
            p = b + "layer%d.%d" % (s + 1, i)
            stride = 2 if (i == 0 and s > 0) else 1
            out = F.relu(norm(conv(x, sd, p + ".conv1", stride, 1), sd, p + ".bn1"))
            out = norm(conv(out, sd, p + ".conv2", 1, 1), sd, p + ".bn2")
            if (p + ".downsample.0.weight") in sd:
                res = norm(conv(x, sd, p + ".downsample.0", stride, 0), sd, p + ".downsample.1")
            else:
                res = x
            x = F.relu(out + res)
        feats.append(x)
    return feats


def u_decode(feats, sd, p):
    x = feats[3]
    for i in range(3):
        x = F.interpolate(x, scale_factor=2, mode="bilinear", align_corners=False)
        x = torch.cat((x, feats[2 - i]), 1)
        x = F.relu(batch_norm(conv(x, sd, "%s.%d.conv" % (p, i), 1, 1), sd, "%s.%d.norm" % (p, i)))
    return F.max_pool2d(x, 2, 2)


def inverse_sigmoid(x, eps=1e-5):
    x = x.clamp(0, 1)
    return torch.log(x.clamp(min=eps) / (1 - x).clamp(min=eps))


# -------------------------------------------------------------------------- geometry
def soft_argmax(hm, crop):
    M, Jn, H, W = hm.shape
    pdf = hm.reshape(M, Jn, H * W)
    pdf = (pdf / (pdf.sum(-1, keepdim=True) + 1e-6)).view(M, Jn, H, W)
    v = (pdf.sum(3) * (torch.arange(H, dtype=torch.float32) / float(H))).sum(-1, keepdim=True)
    u = (pdf.sum(2) * (torch.arange(W, dtype=torch.float32) / float(W))).sum(-1, keepdim=True)
    return torch.cat((u, v), -1) * float(crop)


def triangulate(uv, K, cam_from_master):
    B, N, Jn, _ = uv.shape
    P = torch.matmul(K, cam_from_master[..., 0:3, :])
    A = uv.unsqueeze(-1) * P[..., 2:3, :].unsqueeze(2) - P[..., 0:2, :].unsqueeze(2)
    A = A.permute(0, 2, 1, 3, 4).reshape(B * Jn, 2 * N, 4)
    vt = torch.linalg.svd(A, full_matrices=True)[2]
    last = vt[:, -1, :]
    return (last[:, 0:3] / (last[:, 3:4] + 1e-7)).reshape(B, Jn, 3)


def frustum(K, master_from_cam, S, D, crop, zmin, zmax):
    B, N = K.shape[:2]
    stride = float(crop) / S
    u = torch.arange(S, dtype=torch.float32) * stride
    d = torch.arange(D, dtype=torch.float32) * ((zmax - zmin) / D) + zmin

    def k(r, c):
        return K[..., r, c].view(B, N, 1, 1, 1)

    def t(r, c):
        return master_from_cam[..., r, c].view(B, N, 1, 1, 1)

    uu = u.view(1, 1, S, 1, 1)
    vv = u.view(1, 1, 1, S, 1)
    dd = d.view(1, 1, 1, 1, D).expand(B, N, S, S, D)
    x = (uu - k(0, 2)) / k(0, 0) * dd
    y = (vv - k(1, 2)) / k(1, 1) * dd
    z = dd
    return torch.stack([t(r, 0) * x + t(r, 1) * y + t(r, 2) * z + t(r, 3) for r in range(3)], -1)


def range_tensors(rng):
    lo = torch.tensor(rng[0:3], dtype=torch.float32)
    span = torch.tensor([rng[3] - rng[0], rng[4] - rng[1], rng[5] - rng[2]], dtype=torch.float32)
    return lo, span


def project(points, K, cam_from_master):
    B, P = points.shape[:2]
    x, y, z = (points[:, :, i].view(B, 1, P) for i in range(3))

    def e(m, r, c):
        return m[..., r, c].unsqueeze(-1)

    T = cam_from_master
    pc = [e(T, r, 0) * x + e(T, r, 1) * y + e(T, r, 2) * z + e(T, r, 3) for r in range(3)]
    pu = e(K, 0, 0) * pc[0] + e(K, 0, 1) * pc[1] + e(K, 0, 2) * pc[2]
    pv = e(K, 1, 0) * pc[0] + e(K, 1, 1) * pc[1] + e(K, 1, 2) * pc[2]
    pw = e(K, 2, 0) * pc[0] + e(K, 2, 1) * pc[1] + e(K, 2, 2) * pc[2]
    pw = torch.where(pw.abs() < 1e-7, torch.full_like(pw, 1e-7), pw)
    return torch.stack((pu / pw, pv / pw), -1)


def sine_encoding(N, H, W, F_):
    def axis(n):
        idx = torch.arange(1, n + 1, dtype=torch.float32)
        return idx / (idx[-1:] + 1e-6) * (2 * math.pi)

    c = torch.arange(F_, dtype=torch.float32)
    dim_t = torch.pow(10000.0, 2 * torch.div(c, 2, rounding_mode="floor") / float(F_))

    def enc(pos):
        p = pos.unsqueeze(-1) / dim_t
        return torch.cat((p[:, 0::2].sin(), p[:, 1::2].cos()), -1)

    full = (N, H, W, F_)
    en = enc(axis(N)).view(N, 1, 1, F_).expand(full)
    ey = enc(axis(H)).view(1, H, 1, F_).expand(full)
    ex = enc(axis(W)).view(1, 1, W, F_).expand(full)
    return torch.cat((en, ey, ex), -1).permute(0, 3, 1, 2).contiguous()


def squared_distance(a, b):
    # a (..., 3), b (..., 3) broadcastable; evaluated as dx*dx + dy*dy + dz*dz.
    dx = a[..., 0] - b[..., 0]
    dy = a[..., 1] - b[..., 1]
    dz = a[..., 2] - b[..., 2]
    d = dx * dx
    d = d + dy * dy
    return d + dz * dz


def select_ball(points, center, radius, count):
    """The documented rule: evenly spread over the inside points in index order, or all
    inside points followed by the nearest outside ones (ties: lower index)."""
    out, inside_counts = [], []
    r2 = torch.tensor(radius * radius, dtype=torch.float32)
    for b in range(points.shape[0]):
        d2 = squared_distance(points[b], center[b].view(1, 3))
        inside = torch.nonzero(d2 < r2).flatten()
        m = inside.numel()
        inside_counts.append(m)
        if m >= count:
            out.append(inside[(torch.arange(count, dtype=torch.int64) * m) // count])
        else:
            outside = torch.nonzero(~(d2 < r2)).flatten()
            order = torch.sort(d2[outside], stable=True)[1]
            out.append(torch.cat((inside, outside[order[: count - m]])))
    return torch.stack(out), torch.tensor(inside_counts, dtype=torch.int64)


def knn(query, points, k):
    d2 = squared_distance(query.unsqueeze(2), points.unsqueeze(1))  # (B, Qn, P)
    return torch.sort(d2, dim=-1, stable=True)[1][..., :k]


def gather(values, idx):
    B = values.shape[0]
    return values[torch.arange(B).view(B, 1, 1), idx]


def attention_self(xyz, f, sd, p, k):
    idx = knn(xyz, xyz, k)
    x = lin(f, sd, p + ".fc1")
    q = lin(x, sd, p + ".w_qs")
    kk = gather(lin(x, sd, p + ".w_ks"), idx)
    v = gather(lin(x, sd, p + ".w_vs"), idx)
    pos = mlp(xyz.unsqueeze(2) - gather(xyz, idx), sd, p + ".fc_delta")
    a = mlp(q.unsqueeze(2) - kk + pos, sd, p + ".fc_gamma")
    a = torch.softmax(a / math.sqrt(kk.shape[-1]), dim=-2)
    return lin((a * (v + pos)).sum(2), sd, p + ".fc2") + f


def attention_cross(qxyz, qf, pxyz, pf, sd, p, k):
    idx = knn(qxyz, pxyz, k)
    q = lin(qf, sd, p + ".w_qs")
    x = lin(gather(pf, idx), sd, p + ".fc1")  # fc1 on the gathered point features
    kk = lin(x, sd, p + ".w_ks")
    v = lin(x, sd, p + ".w_vs")
    pos = mlp(qxyz.unsqueeze(2) - gather(pxyz, idx), sd, p + ".fc_delta")
    a = mlp(q.unsqueeze(2) - kk + pos, sd, p + ".fc_gamma")
    a = torch.softmax(a / math.sqrt(kk.shape[-1]), dim=-2)
    return lin((a * (v + pos)).sum(2), sd, p + ".fc2") + qf


def sample_views(feat, grid, B, N):
    s = F.grid_sample(feat, grid, mode="bilinear", padding_mode="zeros", align_corners=False)
    C, P = feat.shape[1], grid.shape[1]
    return s.squeeze(-1).reshape(B, N, C, P).permute(0, 3, 1, 2)


def merge_views(f, sd, p):
    e = mlp(f, sd, p + ".0")
    master, others = e[:, :, 0], e[:, :, 1:]
    s = torch.matmul(others, master.unsqueeze(-1))
    agg = torch.matmul(others.transpose(2, 3), s).squeeze(-1)
    return f[:, :, 0] + mlp(agg, sd, p + ".1")


# ----------------------------------------------------------------------- forward pass
def forward(cfg, sd, images, K, master_from_cam):
    B, N = images.shape[:2]
    S = cfg["crop_size"]
    H = S // 8
    E = cfg["embed_dim"]
    D = cfg["depth_bins"]
    rng = cfg["position_range"]
    out = {}
    feats = backbone(images.reshape(B * N, 3, S, S), sd, cfg)
    feat = conv(u_decode(feats, sd, "feat_delayer"), sd, "feat_in.conv")
    hm = torch.sigmoid(conv(u_decode(feats, sd, "uv_delayer"), sd, "uv_out.conv"))
    out["joints_2d"] = soft_argmax(hm, S).view(B, N, J, 2)
    cam_from_master = torch.linalg.inv(master_from_cam)
    tri = triangulate(out["joints_2d"], K, cam_from_master)
    out["triangulated_joints"] = tri
    root = tri[:, 0:1]
    verts = F.linear((tri - root).transpose(1, 2), sd["linear_inv_skin.weight"],
                     sd["linear_inv_skin.bias"]).transpose(1, 2) + root
    mesh = torch.cat((tri, verts), 1)
    out["initial_mesh"] = mesh

    h = "ptEmb_head."
    x = conv(feat, sd, h + "input_proj")
    fr = frustum(K, master_from_cam, H, D, S, rng[2], rng[5])  # (B, N, W, H, D, 3)
    lo, span = range_tensors(rng)
    coords = ((fr - lo) / span).permute(0, 1, 4, 5, 3, 2).reshape(B * N, 3 * D, H, H)
    coords_embed = conv(F.relu(conv(inverse_sigmoid(coords), sd, h + "position_encoder.0")), sd,
                        h + "position_encoder.2")
    sin_embed = conv(sine_encoding(N, H, H, E // 2), sd, h + "adapt_pos3d").repeat(B, 1, 1, 1)
    pos_embed = sin_embed + coords_embed
    x = x + pos_embed

    shift = mlp(mesh.transpose(1, 2), sd, h + "center_shift_layer").transpose(1, 2)
    center = mesh.mean(1, keepdim=True) + 0.01 * shift
    out["ball_center"] = center.squeeze(1)
    query_embeds = mlp(sd[h + "reference_embed.weight"], sd, h + "query_embedding")
    query_embeds = query_embeds.unsqueeze(0).expand(B, -1, -1)
    mesh_grid = (project(mesh, K, cam_from_master) / float(S) * 2 - 1).reshape(B * N, Q, 1, 2)
    query_feat = merge_views(sample_views(x, mesh_grid, B, N), sd, h + "merge_net_query_feature")

    fr_flat = fr.reshape(B, -1, 3)
    index, inside = select_ball(fr_flat, out["ball_center"], cfg["ball_radius"],
                                cfg["num_sampled_points"])
    out["point_index"] = index
    out["points_inside_ball"] = inside
    points = gather(fr_flat, index.unsqueeze(-1)).squeeze(2)
    out["sampled_points"] = points
    Kp = points.shape[1]
    point_grid = (project(points, K, cam_from_master) / float(S) * 2 - 1).reshape(B * N, Kp, 1, 2)
    point_feat = merge_views(sample_views(x, point_grid, B, N), sd, h + "merge_net_feature")
    point_embed = sample_views(pos_embed, point_grid, B, N).sum(2)

    t = h + "transformer."
    pxyz = (points - lo) / span
    pf = attention_self(pxyz, point_feat + point_embed, sd, t + "feats_self_attn",
                        cfg["point_neighbors"])
    qxyz = (mesh - lo) / span
    qf = query_feat + query_embeds
    layers = []
    for i in range(cfg["num_decoder_blocks"]):
        qf = attention_self(qxyz, qf, sd, t + "query_self_attn.%d" % i, cfg["query_neighbors"])
        qf = attention_cross(qxyz, qf, pxyz, pf, sd, t + "query_feats_cross_attn.%d" % i,
                             cfg["point_neighbors"])
        qxyz = torch.sigmoid(mlp(qf, sd, h + "reg_branches.%d" % i) + inverse_sigmoid(qxyz))
        layers.append(qxyz)
    out["layer_coords"] = torch.nan_to_num(torch.stack(layers)) * span + lo
    return out


# ----------------------------------------------------------------------------- losses
def reference_losses(out, targets, regressor, K, master_from_cam, crop):
    """The reference training losses with the released weights (10, 10, 1, 1, 1)."""
    diag = math.sqrt(2.0 * crop * crop)
    gt_j, gt_v, gt_uv = targets["joints_3d"], targets["vertices_3d"], targets["joints_2d"]
    terms = collections.OrderedDict()
    terms["heatmap_joints"] = (((out["joints_2d"] - gt_uv) / diag) ** 2).sum(-1).mean()
    terms["triangulated_joints"] = F.mse_loss(out["triangulated_joints"], gt_j)
    total = 10 * terms["heatmap_joints"] + 10 * terms["triangulated_joints"]
    extr = torch.linalg.inv(master_from_cam)  # cam_from_master (B, N, 4, 4)
    layers = out["layer_coords"]
    for i in range(layers.shape[0]):
        joints, verts = layers[i][:, :J], layers[i][:, J:]
        j3d = F.mse_loss(joints, gt_j)
        j_mesh = F.mse_loss(regressor @ verts, regressor @ gt_v)
        v3d = F.l1_loss(verts, gt_v)
        n = K.shape[1]
        pts = joints.unsqueeze(1).repeat(1, n, 1, 1)
        cam = (extr[..., :3, :3] @ pts.transpose(2, 3)).transpose(2, 3) + extr[..., :3, 3].unsqueeze(2)
        uvw = (K @ cam.transpose(2, 3)).transpose(2, 3)
        z = uvw[..., 2:].clone()
        z[z.abs() < 1e-7] = 1e-7
        uv = uvw[..., :2] / z
        off = torch.clamp(uv - gt_uv, min=-0.5 * diag, max=0.5 * diag) / diag
        j2d = (off ** 2).sum(-1).mean()
        recon = j3d + j_mesh + v3d + j2d
        terms["dec%d_recon" % i] = recon
        total = total + recon
        if i == layers.shape[0] - 1:
            terms["joints_3d"], terms["joints_3d_from_mesh"] = j3d, j_mesh
            terms["vertices_3d"], terms["joints_2d"] = v3d, j2d
    terms["total"] = total
    return terms


def make_targets(out, gen):
    B = out["triangulated_joints"].shape[0]
    center = out["ball_center"].view(B, 1, 3)
    targets = {
        "joints_3d": center + 0.05 * torch.randn((B, J, 3), generator=gen),
        "vertices_3d": center + 0.05 * torch.randn((B, V, 3), generator=gen),
        "joints_2d": out["joints_2d"] + 5 * torch.randn(out["joints_2d"].shape, generator=gen),
    }
    regressor = torch.rand((J, V), generator=gen) * (torch.rand((J, V), generator=gen) < 0.01)
    return targets, regressor


# --------------------------------------------------------------------------- inputs
def look_at(eye, target, up):
    z = target - eye
    z = z / z.norm()
    x = torch.linalg.cross(up, z)
    x = x / x.norm()
    y = torch.linalg.cross(z, x)
    R = torch.stack((x, y, z))  # rows: camera axes in master coordinates
    T = torch.eye(4, dtype=torch.float64)
    T[:3, :3] = R.T
    T[:3, 3] = eye
    return T  # master_from_cam


def make_inputs(cfg, B, gen):
    N, S = cfg["num_views"], cfg["crop_size"]
    images = torch.rand((B, N, 3, S, S), generator=gen) - 0.5
    K = torch.zeros((B, N, 3, 3))
    M = torch.zeros((B, N, 4, 4))
    for b in range(B):
        center = torch.tensor([0.03 * b, -0.02 * b, 0.6], dtype=torch.float64)
        for n in range(N):
            if n == 0:
                M[b, n] = torch.eye(4)
            else:
                a = 2 * math.pi * n / N
                eye = center + 0.6 * torch.tensor(
                    [math.sin(a), 0.3 * math.cos(3 * a), -math.cos(a)], dtype=torch.float64)
                M[b, n] = look_at(eye, center, torch.tensor([0.0, -1.0, 0.0],
                                                            dtype=torch.float64)).float()
            f = 2.0 * S
            K[b, n] = torch.tensor([[f, 0, S / 2 + 3 * n], [0, 1.01 * f, S / 2 - 2 * n], [0, 0, 1]])
    return images, K, M


def write_bundle(path, tensors):
    manifest, offset = {}, 0
    with open(path + ".bin", "wb") as fbin:
        for name, t in tensors.items():
            t = t.detach().contiguous()
            if t.dtype not in (torch.float32, torch.int64):
                t = t.float()
            data = t.numpy().tobytes()
            manifest[name] = {"dtype": str(t.dtype).replace("torch.", ""),
                              "shape": list(t.shape), "offset": offset}
            fbin.write(data)
            offset += len(data)
    with open(path + ".json", "w") as fjson:
        json.dump(manifest, fjson, indent=1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--batch", type=int, default=2)
    ap.add_argument("--shapes-only", action="store_true",
                    help="write only {key: shape} of the state_dict to OUT/shapes.json")
    args = ap.parse_args()
    torch.set_num_threads(1)
    with open(args.config) as f:
        cfg = json.load(f)
    gen = torch.Generator().manual_seed(args.seed)
    os.makedirs(args.out, exist_ok=True)
    if args.shapes_only:
        sd = random_state_dict(cfg, gen)
        with open(os.path.join(args.out, "shapes.json"), "w") as f:
            json.dump({k: list(v.shape) for k, v in sd.items()}, f, indent=1)
        return
    sd = random_state_dict(cfg, gen)
    torch.save(sd, os.path.join(args.out, "PtEmbedMultiviewStereo.pth.tar"))
    write_bundle(os.path.join(args.out, "weights"), sd)
    images, K, M = make_inputs(cfg, args.batch, gen)
    with torch.no_grad():
        out = forward(cfg, sd, images, K, M)
    write_bundle(os.path.join(args.out, "inputs"),
                 {"images": images, "intrinsics": K, "master_from_cam": M})
    write_bundle(os.path.join(args.out, "outputs"), out)
    targets, regressor = make_targets(out, gen)
    losses = reference_losses(out, targets, regressor, K, M, cfg["crop_size"])
    write_bundle(os.path.join(args.out, "targets"), dict(targets, regressor=regressor))
    write_bundle(os.path.join(args.out, "losses"), {k: v.reshape(1) for k, v in losses.items()})


if __name__ == "__main__":
    main()
