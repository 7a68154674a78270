#pragma once
// The look of synthetic renders. "basic" is the original look (flat skin with
// per-vertex noise, one or two Lambert lights, a floating hand over a procedural
// cluttered background); the shipped network was trained on it, so it stays the
// default and byte-identical. "realistic" is made for real 2D detectors (MediaPipe's
// palm detector rarely fires on basic renders, docs/detector.md):
//   - skin: the scene's skin tone, a lighter and pinker palm side, smooth blotchy
//     variation and ambient occlusion baked per vertex (darker creases between
//     fingers), soft wrap diffuse (light bleeding under the skin, most in red) and a
//     faint highlight;
//   - a forearm continuing the wrist, with the hand's skin;
//   - lighting: ambient + a key light from above + a weaker fill light from the other
//     side;
//   - a table plane under the hand (wood-like or cloth texture) in front of a plain
//     wall, and the hand's soft shadow on the table;
//   - the camera's slight blur and sensor noise over the whole image.
// Everything drawn besides the hand and the objects (forearm, table) is scenery: it
// occludes like an object but is in neither the hand mask nor the object mask.
// The extra draws use their own random stream, so the scene (pose, shape, objects,
// skin tone) of a frame is the same in both looks.

#include <Eigen/Core>
#include <random>
#include <string>

#include "capture/synth_scene.h"
#include "hand/hand_model.h"
#include "image/image.h"

namespace handlabel {

enum class SynthAppearance { kBasic, kRealistic };

// "basic" | "realistic"; throws InputError naming `source` and `field` otherwise.
SynthAppearance SynthAppearanceFromName(const std::string& name,
                                        const std::string& source,
                                        const std::string& field);
std::string SynthAppearanceName(SynthAppearance appearance);

struct RealisticLookOptions {
  bool forearm = true;          // draw the forearm
  bool table = true;            // draw the table plane (else the wall fills the view)
  double table_height = -0.2;   // world z of the table top (m; world z is up)
  double forearm_length = 0.4;  // metres from the wrist (mostly leaves the image)
  double blur = 0.6;            // sigma (px) of the camera blur, 0 = none
  double max_noise = 4.0;       // sensor noise sigma (8-bit levels), drawn in [1, this]
  // The world direction the key and fill lights come down from (any length > 0). A
  // capture's world need not have z up: the development recording's world is its master
  // camera's frame, where +z points into the table (capture_look.h picks "up" from the
  // cameras). The table is the plane z = table_height, so it needs up = +z.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

// Re-skins the scene's hand, replaces its lighting and adds the scenery. Deterministic
// in `rng`; the scene's pose, shape, objects and skin tone are kept.
void ApplyRealisticLook(const HandModel& model, const RealisticLookOptions& options,
                        std::mt19937_64& rng, SynthScene* scene);

// A plain wall: a muted colour with a soft vertical gradient and faint smooth blotches.
ImageU8 MakeWallBackground(int width, int height, std::mt19937_64& rng);

// The camera's blur (Gaussian, sigma px) and sensor noise (sigma levels), in place.
void ApplyCameraBlurAndNoise(double blur_sigma, double noise_sigma, std::mt19937_64& rng,
                             ImageU8* rgb);

}  // namespace handlabel
