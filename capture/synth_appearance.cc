#include "capture/synth_appearance.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/gaussian_blur.h"

namespace handlabel {
namespace {

float Smoothstep(float lo, float hi, float x) {
  const float t = std::clamp((x - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3 - 2 * t);
}

// Smooth 3D value noise in [0, 1]: trilinear interpolation of a hashed lattice.
class ValueNoise3 {
 public:
  explicit ValueNoise3(std::mt19937_64& rng) {
    for (float& v : table_) v = static_cast<float>(Uniform(rng, 0, 1));
  }
  float operator()(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d f = p.array().floor();
    const Eigen::Vector3d t = p - f;
    float out = 0;
    for (int corner = 0; corner < 8; ++corner) {
      float w = 1;
      int h = 0;
      for (int a = 0; a < 3; ++a) {
        const int bit = (corner >> a) & 1;
        const float s = static_cast<float>(t[a] * t[a] * (3 - 2 * t[a]));
        w *= bit ? s : 1 - s;
        h = h * 31 + static_cast<int>(f[a]) + bit;
      }
      out += w * table_[static_cast<unsigned>(h * 2654435761u) % table_.size()];
    }
    return out;
  }

 private:
  std::array<float, 256> table_{};
};

// Ambient occlusion per vertex from the mesh itself: the share of nearby vertices that
// lie in front of the vertex (inside its normal's cone), weighted by closeness. Cheap
// (V^2 on a ~800-vertex hand) and enough to darken creases between fingers.
std::vector<float> VertexOcclusion(const Points3d& v, const Points3d& n, double radius) {
  std::vector<float> occ(v.rows(), 0.0f);
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    double sum = 0;
    for (Eigen::Index j = 0; j < v.rows(); ++j) {
      const Eigen::Vector3d d = (v.row(j) - v.row(i)).transpose();
      const double dist = d.norm();
      if (dist < 1e-6 || dist > radius) continue;
      const double facing = n.row(i).dot(d) / dist;
      if (facing > 0.3) sum += facing * (1 - dist / radius);
    }
    occ[i] = static_cast<float>(std::min(1.0, sum / 25.0));
  }
  return occ;
}

// Skin: the tone, lighter and pinker on the palm side, smooth blotches, baked AO.
void ReskinHand(const HandModel& model, std::mt19937_64& rng, SynthScene* scene) {
  RenderMesh& hand = scene->hand_render;
  const Eigen::Vector3f tone = scene->skin;
  // Palm side from the flat template (palm faces -y there, as synth_scene.cc assumes).
  const Points3d template_normals = ComputeVertexNormals(model.v_template, model.faces);
  const Eigen::Vector3f palm_tone = (tone.array() * Eigen::Array3f(1.12f, 1.02f, 1.0f) +
                                     Eigen::Array3f(0.04f, 0.0f, 0.0f))
                                        .min(1.0f)
                                        .matrix();
  const ValueNoise3 noise(rng);
  const double blotch_scale = Uniform(rng, 40, 80);  // cycles per metre
  const std::vector<float> occ = VertexOcclusion(hand.vertices, hand.normals, 0.025);
  for (Eigen::Index v = 0; v < hand.vertices.rows(); ++v) {
    const float palm =
        Smoothstep(0.0f, 0.6f, static_cast<float>(-template_normals(v, 1)));
    Eigen::Vector3f albedo = (1 - palm) * tone + palm * palm_tone;
    const float blotch =
        0.9f + 0.2f * noise(blotch_scale * Eigen::Vector3d(model.v_template.row(v)));
    const float ao = 1.0f - 0.45f * occ[v];
    hand.colors.row(v) = (blotch * ao * albedo).cwiseMin(1.0f).transpose();
  }
}

// The wrist's cross-section: centre and two half-axes (metres) of the hand vertices
// near the wrist, in the plane across `axis`.
struct CrossSection {
  Eigen::Vector3d centre, u, v;
  double a = 0.03, b = 0.02;
};

CrossSection WristSection(const Points3d& vertices, const Eigen::Vector3d& wrist,
                          const Eigen::Vector3d& axis) {
  std::vector<Eigen::Vector3d> q;
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    const Eigen::Vector3d d = vertices.row(i).transpose() - wrist;
    const double t = d.dot(axis);
    if (t > -0.015 && t < 0.01) q.push_back(d - t * axis);
  }
  CrossSection s;
  s.centre = wrist;
  s.u = axis.unitOrthogonal();
  s.v = axis.cross(s.u);
  if (q.size() < 8) return s;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : q) mean += p;
  mean /= static_cast<double>(q.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : q) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  s.centre = wrist + mean;
  s.u = eig.eigenvectors().col(2).normalized();  // widest direction
  s.v = axis.cross(s.u).normalized();
  s.a = s.b = 0;
  for (const auto& p : q) {
    s.a = std::max(s.a, std::abs((p - mean).dot(s.u)));
    s.b = std::max(s.b, std::abs((p - mean).dot(s.v)));
  }
  s.a = std::clamp(s.a, 0.015, 0.05);
  s.b = std::clamp(s.b, 0.01, 0.04);
  return s;
}

// A forearm: an elliptic tube from just inside the wrist towards the elbow, widening
// and rounding, closed at the far end.
RenderMesh MakeForearm(const SynthScene& scene, double length, std::mt19937_64& rng) {
  const Points3d& k = scene.hand.keypoints;
  const Eigen::Vector3d wrist = k.row(0).transpose();
  const Eigen::Vector3d axis = (wrist - k.row(9).transpose()).normalized();
  const CrossSection s = WristSection(scene.hand.vertices, wrist, axis);
  constexpr int kAround = 24, kAlong = 20;
  const double grow_a = Uniform(rng, 0.15, 0.35), grow_b = Uniform(rng, 0.4, 0.8);
  RenderMesh arm;
  arm.vertices.resize(kAround * (kAlong + 1) + 1, 3);
  for (int i = 0; i <= kAlong; ++i) {
    const double f = static_cast<double>(i) / kAlong;
    const double t = -0.012 + f * (length + 0.012);
    // The last tenth rounds off (an elbow-like end rather than a cut tube).
    const double end =
        f > 0.9 ? std::sqrt(std::max(0.0, 1 - std::pow((f - 0.9) / 0.1, 2))) : 1.0;
    const double a = s.a * (1 + grow_a * f) * 0.92 * std::max(end, 0.05),
                 b = s.b * (1 + grow_b * f) * 0.92 * std::max(end, 0.05);
    for (int j = 0; j < kAround; ++j) {
      const double phi = 2 * M_PI * j / kAround;
      arm.vertices.row(i * kAround + j) =
          (s.centre + t * axis + a * std::cos(phi) * s.u + b * std::sin(phi) * s.v)
              .transpose();
    }
  }
  const int cap = kAround * (kAlong + 1);
  arm.vertices.row(cap) = (s.centre + length * axis).transpose();
  std::vector<Eigen::Vector3i> faces;
  for (int i = 0; i < kAlong; ++i) {
    for (int j = 0; j < kAround; ++j) {
      const int p = i * kAround + j, q = i * kAround + (j + 1) % kAround;
      faces.emplace_back(p, q, q + kAround);
      faces.emplace_back(p, q + kAround, p + kAround);
    }
  }
  for (int j = 0; j < kAround; ++j) {
    faces.emplace_back(kAlong * kAround + j, kAlong * kAround + (j + 1) % kAround, cap);
  }
  arm.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) arm.faces.row(f) = faces[f].transpose();
  arm.normals = ComputeVertexNormals(arm.vertices, arm.faces);
  // The arm's skin: the back-of-hand tone, slightly lighter towards the elbow.
  arm.colors.resize(arm.vertices.rows(), 3);
  for (Eigen::Index v = 0; v < arm.vertices.rows(); ++v) {
    const double t = (arm.vertices.row(v).transpose() - wrist).dot(axis) / length;
    arm.colors.row(v) =
        (scene.skin * static_cast<float>(0.97 + 0.06 * std::clamp(t, 0.0, 1.0)))
            .cwiseMin(1.0f)
            .transpose();
  }
  return arm;
}

// The table's texture (2 m x 2 m, 4 mm texels): wood grain or cloth, with the soft
// shadow of everything above it cast by the key light.
std::shared_ptr<const ImageU8> MakeTableTexture(const SynthScene& scene, double extent,
                                                double height,
                                                const Eigen::Vector3d& light_travel,
                                                std::mt19937_64& rng) {
  constexpr int kSize = 512;
  auto tex = std::make_shared<ImageU8>(kSize, kSize, 3);
  const bool wood = Uniform(rng, 0, 1) < 0.5;
  Eigen::Vector3f base;
  if (wood) {
    base =
        Eigen::Vector3f(0.55f, 0.38f, 0.22f) * static_cast<float>(Uniform(rng, 0.6, 1.3));
  } else {
    const float grey = static_cast<float>(Uniform(rng, 0.25, 0.85));
    base = Eigen::Vector3f(grey * static_cast<float>(Uniform(rng, 0.9, 1.1)), grey,
                           grey * static_cast<float>(Uniform(rng, 0.9, 1.1)));
  }
  const ValueNoise3 noise(rng);
  const double grain_angle = Uniform(rng, 0, M_PI);
  const double gc = std::cos(grain_angle), gs = std::sin(grain_angle);
  // Shadow: everything above the table projected along the light onto it, splatted
  // into a coarse density grid and blurred (soft edges).
  std::vector<float> shadow(kSize * kSize, 0.0f);
  auto splat = [&](const Points3d& vertices) {
    for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
      const Eigen::Vector3d p = vertices.row(i).transpose();
      if (p.z() <= height || light_travel.z() >= -1e-3) continue;
      const Eigen::Vector3d hit =
          p + ((height - p.z()) / light_travel.z()) * light_travel;
      const int x = static_cast<int>((hit.x() / extent + 0.5) * kSize);
      const int y = static_cast<int>((hit.y() / extent + 0.5) * kSize);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (x + dx >= 0 && x + dx < kSize && y + dy >= 0 && y + dy < kSize)
            shadow[(y + dy) * kSize + x + dx] = 1.0f;
    }
  };
  splat(scene.hand_render.vertices);
  for (const RenderMesh& m : scene.scenery) splat(m.vertices);
  for (const SynthObject& o : scene.objects) splat(o.mesh.vertices);
  // Box blur three times ~ Gaussian, radius 4 texels each pass (~2.8 cm overall).
  std::vector<float> tmp(shadow.size());
  for (int pass = 0; pass < 3; ++pass) {
    for (int dir = 0; dir < 2; ++dir) {
      for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
          float sum = 0;
          for (int d = -4; d <= 4; ++d) {
            const int xx = dir == 0 ? std::clamp(x + d, 0, kSize - 1) : x;
            const int yy = dir == 1 ? std::clamp(y + d, 0, kSize - 1) : y;
            sum += shadow[yy * kSize + xx];
          }
          tmp[y * kSize + x] = sum / 9.0f;
        }
      }
      shadow.swap(tmp);
    }
  }
  const float shadow_strength = static_cast<float>(Uniform(rng, 0.35, 0.6));
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double u = extent * x / kSize, v = extent * y / kSize;
      float shade;
      if (wood) {
        const double along = gc * u + gs * v, across = -gs * u + gc * v;
        const float warp = noise(Eigen::Vector3d(3 * along, 40 * across, 0.5));
        shade = 0.85f + 0.15f * std::sin(static_cast<float>(90 * across + 6 * warp));
      } else {
        shade = 0.92f + 0.12f * noise(Eigen::Vector3d(120 * u, 120 * v, 1.5));
      }
      shade *= 1.0f - shadow_strength * std::min(1.0f, 1.5f * shadow[y * kSize + x]);
      for (int c = 0; c < 3; ++c)
        tex->at(x, y, c) =
            static_cast<uint8_t>(std::clamp(255.0f * shade * base[c], 0.0f, 255.0f));
    }
  }
  return tex;
}

// A square table top at world z = height, extent metres wide, centred under the origin,
// tessellated finely enough for the rasteriser (image/rasterizer.h).
RenderMesh MakeTable(double extent, double height) {
  constexpr int kCells = 80;
  RenderMesh table;
  table.vertices.resize((kCells + 1) * (kCells + 1), 3);
  table.uvs.resize(table.vertices.rows(), 2);
  for (int y = 0; y <= kCells; ++y) {
    for (int x = 0; x <= kCells; ++x) {
      const int i = y * (kCells + 1) + x;
      const double fx = static_cast<double>(x) / kCells,
                   fy = static_cast<double>(y) / kCells;
      table.vertices.row(i) << (fx - 0.5) * extent, (fy - 0.5) * extent, height;
      table.uvs.row(i) << static_cast<float>(fx), static_cast<float>(fy);
    }
  }
  table.faces.resize(2 * kCells * kCells, 3);
  int f = 0;
  for (int y = 0; y < kCells; ++y) {
    for (int x = 0; x < kCells; ++x) {
      const int p = y * (kCells + 1) + x;
      table.faces.row(f++) << p, p + 1, p + kCells + 2;
      table.faces.row(f++) << p, p + kCells + 2, p + kCells + 1;
    }
  }
  table.normals = Points3d::Zero(table.vertices.rows(), 3);
  table.normals.col(2).setOnes();
  table.color = Eigen::Vector3f::Ones();
  return table;
}

// Ambient + key light from above (`up`, unit) + fill light from the other side, soft
// skin diffuse. Azimuths turn about `up` from the world x axis (or y, if x is nearly
// up), so that up = +z gives the same lights as before `up` existed.
ShadingOptions RealisticLighting(const Eigen::Vector3d& up, std::mt19937_64& rng) {
  ShadingOptions s;
  const float warmth = static_cast<float>(Uniform(rng, -0.05, 0.05));
  // Ambient + key + fill stay below ~1.15 in total, so that light skin is not
  // overexposed to white where the key light hits it.
  s.ambient = static_cast<float>(Uniform(rng, 0.18, 0.3)) *
              Eigen::Vector3f(1 + warmth, 1, 1 - warmth);
  const double azimuth = Uniform(rng, 0, 2 * M_PI);
  const double key_elevation = Uniform(rng, 40, 80) * M_PI / 180;
  const double fill_elevation = Uniform(rng, 10, 40) * M_PI / 180;
  const Eigen::Vector3d x_axis =
      std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = (x_axis - x_axis.dot(up) * up).normalized();
  const Eigen::Vector3d e2 = up.cross(e1);
  auto from = [&](double az, double el) {
    return Eigen::Vector3d(std::cos(el) * std::cos(az) * e1 +
                           std::cos(el) * std::sin(az) * e2 + std::sin(el) * up);
  };
  DirectionalLight key, fill;
  key.direction_in_world = -from(azimuth, key_elevation);
  key.color = static_cast<float>(Uniform(rng, 0.45, 0.65)) * Eigen::Vector3f(1, 1, 1);
  fill.direction_in_world =
      -from(azimuth + M_PI + Uniform(rng, -0.8, 0.8), fill_elevation);
  fill.color = static_cast<float>(Uniform(rng, 0.1, 0.2)) *
               Eigen::Vector3f(1 - warmth, 1, 1 + warmth);
  s.lights = {key, fill};
  s.wrap = Eigen::Vector3f(0.45f, 0.3f, 0.25f);  // light bleeds under skin, most in red
  s.specular = static_cast<float>(Uniform(rng, 0.03, 0.08));
  s.shininess = 18.0f;
  return s;
}

}  // namespace

void RealisticLookOptions::Check(const std::string& source) const {
  // Open at both ends, so not RequireInRange.
  if (!(forearm_length > 0.02 && forearm_length < 1)) {
    throw InputError(source, "forearm_length", "0.02..1 m",
                     OptionValueText(forearm_length));
  }
  if (!std::isfinite(table_height)) throw InputError(source, "table_height", "finite");
  RequireInRange(source, "blur", blur, 0, 3, "0..3 px");
  RequireInRange(source, "max_noise", max_noise, 1, 30, "1..30 levels");
  if (!up.allFinite() || up.norm() < 1e-9) {
    throw InputError(source, "up", "a finite direction of non-zero length");
  }
  if (table && (up.normalized() - Eigen::Vector3d::UnitZ()).norm() > 1e-9) {
    throw InputError(source, "table",
                     "off unless up is +z (the table is the plane z = table_height)");
  }
}

void ApplyRealisticLook(const HandModel& model, const RealisticLookOptions& options,
                        std::mt19937_64& rng, SynthScene* scene) {
  ReskinHand(model, rng, scene);
  scene->lighting = RealisticLighting(options.up.normalized(), rng);
  if (options.forearm) {
    scene->scenery.push_back(MakeForearm(*scene, options.forearm_length, rng));
  }
  if (options.table) {
    constexpr double kExtent = 2.0;
    RenderMesh table = MakeTable(kExtent, options.table_height);
    table.texture = MakeTableTexture(*scene, kExtent, options.table_height,
                                     scene->lighting.lights[0].direction_in_world, rng);
    scene->scenery.push_back(std::move(table));
  }
}

ImageU8 MakeWallBackground(int width, int height, std::mt19937_64& rng) {
  ImageU8 img(width, height, 3);
  const float grey = static_cast<float>(Uniform(rng, 0.2, 0.75));
  Eigen::Vector3f tint(static_cast<float>(Uniform(rng, 0.85, 1.15)), 1.0f,
                       static_cast<float>(Uniform(rng, 0.85, 1.15)));
  const float top = static_cast<float>(Uniform(rng, 0.85, 1.15));
  const ValueNoise3 noise(rng);
  for (int y = 0; y < height; ++y) {
    const float t = static_cast<float>(y) / std::max(1, height - 1);
    for (int x = 0; x < width; ++x) {
      const float blotch =
          0.95f + 0.1f * noise(Eigen::Vector3d(6.0 * x / width, 6.0 * y / width, 2.5));
      const float value = grey * ((1 - t) * top + t) * blotch;
      for (int c = 0; c < 3; ++c) {
        img.at(x, y, c) =
            static_cast<uint8_t>(std::clamp(255.0f * value * tint[c], 0.0f, 255.0f));
      }
    }
  }
  return img;
}

void ApplyCameraBlurAndNoise(double blur_sigma, double noise_sigma, std::mt19937_64& rng,
                             ImageU8* rgb) {
  const int w = rgb->width, h = rgb->height;
  if (blur_sigma > 0) {
    std::vector<float> a(rgb->data.begin(), rgb->data.end());
    GaussianBlurInPlace(blur_sigma, FloatImageLayout::Interleaved(w, h, 3), a.data());
    for (size_t i = 0; i < a.size(); ++i)
      rgb->data[i] = static_cast<uint8_t>(std::clamp(std::lround(a[i]), 0L, 255L));
  }
  if (noise_sigma > 0) {
    std::normal_distribution<float> gauss(0.0f, static_cast<float>(noise_sigma));
    for (uint8_t& v : rgb->data) {
      v = static_cast<uint8_t>(std::clamp(std::lround(v + gauss(rng)), 0L, 255L));
    }
  }
}

}  // namespace handlabel
