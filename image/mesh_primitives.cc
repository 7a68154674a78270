#include "image/mesh_primitives.h"

#include <cmath>
#include <vector>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Builds a mesh from growing lists.
struct MeshBuilder {
  std::vector<Eigen::Vector3d> v, n;
  std::vector<Eigen::Vector2f> uv;
  std::vector<Eigen::Vector3i> f;

  int Add(const Eigen::Vector3d& p, const Eigen::Vector3d& normal, float u, float w) {
    v.push_back(p);
    n.push_back(normal);
    uv.emplace_back(u, w);
    return static_cast<int>(v.size()) - 1;
  }
  // Quad a b c d counter-clockwise seen from outside.
  void Quad(int a, int b, int c, int d) {
    f.emplace_back(a, b, c);
    f.emplace_back(a, c, d);
  }
  RenderMesh Build() const {
    RenderMesh m;
    m.vertices.resize(v.size(), 3);
    m.normals.resize(v.size(), 3);
    m.uvs.resize(v.size(), 2);
    for (size_t i = 0; i < v.size(); ++i) {
      m.vertices.row(i) = v[i].transpose();
      m.normals.row(i) = n[i].transpose();
      m.uvs.row(i) = uv[i].transpose();
    }
    m.faces.resize(f.size(), 3);
    for (size_t i = 0; i < f.size(); ++i) m.faces.row(i) = f[i].transpose();
    return m;
  }
};

// A grid patch: origin + s * du + t * dv for s, t in [0, 1]; normal = du x dv.
void AddPatch(MeshBuilder* b, const Eigen::Vector3d& origin, const Eigen::Vector3d& du,
              const Eigen::Vector3d& dv, int nu, int nv) {
  const Eigen::Vector3d normal = du.cross(dv).normalized();
  const int start = static_cast<int>(b->v.size());
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double s = static_cast<double>(i) / nu, t = static_cast<double>(j) / nv;
      b->Add(origin + s * du + t * dv, normal, static_cast<float>(s),
             static_cast<float>(t));
    }
  }
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int a = start + j * (nu + 1) + i;
      b->Quad(a, a + 1, a + nu + 2, a + nu + 1);
    }
  }
}

}  // namespace

RenderMesh MakeSphere(double radius, int rings, int segments) {
  HL_CHECK(radius > 0 && rings >= 3 && segments >= 3, "bad sphere parameters");
  MeshBuilder b;
  for (int i = 0; i <= rings; ++i) {
    const double theta = kPi * i / rings;  // from +z (north pole) down
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi),
                              std::sin(theta) * std::sin(phi), std::cos(theta));
      b.Add(radius * n, n, static_cast<float>(j) / segments,
            static_cast<float>(i) / rings);
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * (segments + 1) + j;
      const int c = a + segments + 1;
      // Counter-clockwise from outside: (a, c, c+1, a+1).
      if (i > 0) b.f.emplace_back(a, c, a + 1);
      if (i < rings - 1) b.f.emplace_back(a + 1, c, c + 1);
    }
  }
  return b.Build();
}

RenderMesh MakeBox(const Eigen::Vector3d& size, int divisions) {
  HL_CHECK((size.array() > 0).all() && divisions >= 1, "bad box parameters");
  MeshBuilder b;
  const Eigen::Vector3d h = 0.5 * size;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      Eigen::Vector3d du = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
      du[a1] = size[a1];
      dv[a2] = size[a2];
      Eigen::Vector3d origin = -h;
      origin[axis] = sign * h[axis];
      if (sign < 0) {  // flip so that du x dv points outwards
        std::swap(du, dv);
        origin = -h;
        origin[axis] = -h[axis];
      }
      AddPatch(&b, origin, du, dv, divisions, divisions);
    }
  }
  return b.Build();
}

RenderMesh MakeCylinder(double radius, double height, int segments, int stacks) {
  HL_CHECK(radius > 0 && height > 0 && segments >= 3 && stacks >= 1,
           "bad cylinder parameters");
  MeshBuilder b;
  for (int k = 0; k <= stacks; ++k) {
    const double z = -0.5 * height + height * k / stacks;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      const Eigen::Vector3d n(std::cos(phi), std::sin(phi), 0);
      b.Add(Eigen::Vector3d(radius * n.x(), radius * n.y(), z), n,
            static_cast<float>(j) / segments, static_cast<float>(k) / stacks);
    }
  }
  for (int k = 0; k < stacks; ++k) {
    for (int j = 0; j < segments; ++j) {
      const int a = k * (segments + 1) + j;
      b.Quad(a, a + 1, a + segments + 2, a + segments + 1);
    }
  }
  // Caps: a centre vertex and a ring per end.
  for (int sign : {-1, 1}) {
    const Eigen::Vector3d n(0, 0, sign);
    const int centre = b.Add(Eigen::Vector3d(0, 0, 0.5 * sign * height), n, 0.5f, 0.5f);
    const int ring = static_cast<int>(b.v.size());
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      b.Add(Eigen::Vector3d(radius * std::cos(phi), radius * std::sin(phi),
                            0.5 * sign * height),
            n, static_cast<float>(0.5 + 0.5 * std::cos(phi)),
            static_cast<float>(0.5 + 0.5 * std::sin(phi)));
    }
    for (int j = 0; j < segments; ++j) {
      const int a = ring + j, c = ring + (j + 1) % segments;
      if (sign > 0) {
        b.f.emplace_back(centre, a, c);
      } else {
        b.f.emplace_back(centre, c, a);
      }
    }
  }
  return b.Build();
}

RenderMesh MakePlane(const Eigen::Vector2d& size, int nx, int ny) {
  HL_CHECK(size.x() > 0 && size.y() > 0 && nx >= 1 && ny >= 1, "bad plane parameters");
  MeshBuilder b;
  AddPatch(&b, Eigen::Vector3d(-0.5 * size.x(), -0.5 * size.y(), 0),
           Eigen::Vector3d(size.x(), 0, 0), Eigen::Vector3d(0, size.y(), 0), nx, ny);
  return b.Build();
}

void TransformMesh(const Rigid3& world_from_mesh, RenderMesh* mesh) {
  const Eigen::Matrix3d r = world_from_mesh.rotation.toRotationMatrix();
  for (Eigen::Index i = 0; i < mesh->vertices.rows(); ++i) {
    mesh->vertices.row(i) =
        (r * mesh->vertices.row(i).transpose() + world_from_mesh.translation).transpose();
  }
  for (Eigen::Index i = 0; i < mesh->normals.rows(); ++i) {
    mesh->normals.row(i) = (r * mesh->normals.row(i).transpose()).transpose();
  }
}

}  // namespace handlabel
