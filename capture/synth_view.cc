#include "capture/synth_view.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"

namespace handlabel {

void SynthViewOptions::Check(const std::string& source) const {
  RequireGreater(source, "self_occlusion_tolerance", self_occlusion_tolerance, 0);
  realistic.Check("realistic look options");
  if (background.max_shapes < 0 || !(background.max_noise >= 0)) {
    throw InputError(source, "background", "max_shapes, max_noise >= 0");
  }
}

namespace {

// Pixels of a drawn one's edge that take the render's blur and noise too, so the
// render's edges blend into a photograph.
constexpr int kBlendPx = 2;

// Over a photograph the camera's blur and noise belong to the rendered pixels only (the
// photograph has its own, and a whole-image pass costs more than the render): they are
// applied to the drawn pixels' bounding box and kept within kBlendPx of a drawn pixel.
void ApplyCameraEffectsToDrawn(const VisibilityBuffer& buffer, double blur_sigma,
                               double noise_sigma, std::mt19937_64& rng, ImageU8* rgb) {
  const int w = buffer.width, h = buffer.height;
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (buffer.mesh_id[buffer.index(x, y)] < 0) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) return;  // nothing drawn
  const int margin = kBlendPx + static_cast<int>(std::ceil(3 * blur_sigma));
  x0 = std::max(0, x0 - margin), y0 = std::max(0, y0 - margin);
  x1 = std::min(w - 1, x1 + margin), y1 = std::min(h - 1, y1 + margin);
  ImageU8 box(x1 - x0 + 1, y1 - y0 + 1, 3);
  for (int y = y0; y <= y1; ++y) {
    std::copy_n(&rgb->at(x0, y), 3 * box.width, &box.at(0, y - y0));
  }
  ApplyCameraBlurAndNoise(blur_sigma, noise_sigma, rng, &box);
  const auto near_drawn = [&](int x, int y) {
    for (int dy = -kBlendPx; dy <= kBlendPx; ++dy) {
      for (int dx = -kBlendPx; dx <= kBlendPx; ++dx) {
        const int u = x + dx, v = y + dy;
        if (u >= 0 && v >= 0 && u < w && v < h && buffer.mesh_id[buffer.index(u, v)] >= 0) {
          return true;
        }
      }
    }
    return false;
  };
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      if (near_drawn(x, y)) std::copy_n(&box.at(x - x0, y - y0), 3, &rgb->at(x, y));
    }
  }
}

}  // namespace

SynthView RenderSynthView(const SynthScene& scene, const RigCamera& camera,
                          const PixelRays& rays, const SynthViewOptions& options,
                          std::mt19937_64& background_rng,
                          const ImageU8* photo_background) {
  const int w = camera.camera.width(), h = camera.camera.height();
  SynthView view;
  VisibilityBuffer buffer;
  buffer.Reset(w, h);
  // Mesh ids: 0 = hand, k = object k - 1.
  RasterizeMesh(scene.hand_render, 0, camera.cam_from_world, rays, &buffer);
  for (int m : buffer.mesh_id) view.hand_pixels_unoccluded += m == 0;
  std::vector<const RenderMesh*> meshes = {&scene.hand_render};
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    RasterizeMesh(scene.objects[i].mesh, static_cast<int>(i + 1), camera.cam_from_world,
                  rays, &buffer);
    meshes.push_back(&scene.objects[i].mesh);
  }
  // Scenery after the objects: ids above every object id, in no mask.
  const int first_scenery = static_cast<int>(meshes.size());
  for (const RenderMesh& mesh : scene.scenery) {
    RasterizeMesh(mesh, static_cast<int>(meshes.size()), camera.cam_from_world, rays,
                  &buffer);
    meshes.push_back(&mesh);
  }

  const bool realistic = options.appearance == SynthAppearance::kRealistic;
  if (photo_background) {
    view.rgb = *photo_background;
  } else {
    view.rgb = realistic ? MakeWallBackground(w, h, background_rng)
                         : MakeBackground(w, h, options.background, background_rng);
  }
  ShadeVisible(meshes, buffer, camera.cam_from_world, rays, scene.lighting, &view.rgb);
  if (realistic) {
    const double noise = Uniform(background_rng, 1.0, options.realistic.max_noise);
    if (photo_background) {
      ApplyCameraEffectsToDrawn(buffer, options.realistic.blur, noise, background_rng,
                                &view.rgb);
    } else {
      ApplyCameraBlurAndNoise(options.realistic.blur, noise, background_rng, &view.rgb);
    }
  }
  view.hand_mask = ImageU8(w, h, 1);
  view.object_mask = ImageU8(w, h, 1);
  for (size_t i = 0; i < buffer.mesh_id.size(); ++i) {
    const int m = buffer.mesh_id[i];
    if (m == 0) {
      view.hand_mask.data[i] = 255;
      ++view.hand_pixels;
    } else if (m > 0 && m < first_scenery) {
      view.object_mask.data[i] = static_cast<uint8_t>(m);
    }
  }
  if (options.depth) {
    view.depth = ImageF(w, h, 1);
    for (size_t i = 0; i < buffer.depth.size(); ++i) {
      view.depth.data[i] = std::isfinite(buffer.depth[i]) ? buffer.depth[i] : 0.0f;
    }
  }

  int in_frame = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector3d p =
        camera.cam_from_world * Eigen::Vector3d(scene.hand.keypoints.row(k));
    Eigen::Vector2d uv(std::nan(""), std::nan(""));
    const bool front = camera.camera.Project(p, &uv);
    view.keypoints.row(k) = uv.transpose();
    if (!front || !camera.camera.InImage(uv)) {
      view.visibility[k] = kOutOfFrame;
      continue;
    }
    ++in_frame;
    const int x = std::clamp(static_cast<int>(std::lround(uv.x())), 0, w - 1);
    const int y = std::clamp(static_cast<int>(std::lround(uv.y())), 0, h - 1);
    const size_t i = buffer.index(x, y);
    const int m = buffer.mesh_id[i];
    const bool object_in_front = m > 0 && buffer.depth[i] < p.z();
    const bool hand_in_front =
        m == 0 && buffer.depth[i] < p.z() - options.self_occlusion_tolerance;
    view.visibility[k] = object_in_front || hand_in_front ? kOccluded : kVisible;
    view.behind_object[k] = object_in_front;
  }
  view.status = view.hand_pixels > 0                              ? "visible"
                : in_frame > 0 || view.hand_pixels_unoccluded > 0 ? "occluded"
                                                                  : "out_of_frame";
  return view;
}

}  // namespace handlabel
