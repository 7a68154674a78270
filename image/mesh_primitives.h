#pragma once
// Tessellated primitive meshes (centred at the origin, outward-facing counter-clockwise
// faces, uv coordinates in [0, 1]) for synthetic scenes: objects held in the hand,
// calibration boards. Fine tessellation keeps triangles small, which the rasteriser's
// distortion handling relies on (rasterizer.h).

#include "image/rasterizer.h"

namespace handlabel {

// Sphere of `radius`: `rings` latitude bands x `segments` longitudes (>= 3 each).
RenderMesh MakeSphere(double radius, int rings = 16, int segments = 24);

// Axis-aligned box with the given edge lengths; each face is a `divisions` x
// `divisions` grid of quads (two triangles each); faces do not share vertices, so
// normals stay sharp.
RenderMesh MakeBox(const Eigen::Vector3d& size, int divisions = 4);

// Cylinder along z from -height/2 to +height/2, with capped ends; `segments` around,
// `stacks` along the axis.
RenderMesh MakeCylinder(double radius, double height, int segments = 24, int stacks = 4);

// A flat rectangle in the z = 0 plane, x in [-size.x/2, size.x/2], y likewise, facing
// +z, as a grid of `nx` x `ny` quads (e.g. a calibration board; uv = (x, y) scaled
// to [0, 1] with v down along +y).
RenderMesh MakePlane(const Eigen::Vector2d& size, int nx = 8, int ny = 8);

// Moves every vertex (and rotates normals): p -> world_from_mesh * p.
void TransformMesh(const Rigid3& world_from_mesh, RenderMesh* mesh);

}  // namespace handlabel
