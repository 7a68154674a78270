#include "capture/synth_view.h"

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

SynthView RenderSynthView(const SynthScene& scene, const RigCamera& camera,
                          const PixelRays& rays, const SynthViewOptions& options,
                          std::mt19937_64& background_rng) {
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
  view.rgb = realistic ? MakeWallBackground(w, h, background_rng)
                       : MakeBackground(w, h, options.background, background_rng);
  ShadeVisible(meshes, buffer, camera.cam_from_world, rays, scene.lighting, &view.rgb);
  if (realistic) {
    const double noise = Uniform(background_rng, 1.0, options.realistic.max_noise);
    ApplyCameraBlurAndNoise(options.realistic.blur, noise, background_rng, &view.rgb);
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
