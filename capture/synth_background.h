#pragma once
// Procedural cluttered backgrounds for synthetic views: a base (flat colour, linear
// gradient or smooth value noise), optional stripes or checker texture, random
// rectangles and ellipses, and pixel noise. Deterministic in `rng`.

#include <random>

#include "image/image.h"

namespace handlabel {

struct BackgroundOptions {
  // Random rectangles/ellipses drawn over the base (at most).
  int max_shapes = 12;
  // Standard deviation of per-pixel Gaussian noise, in 8-bit levels (at most).
  double max_noise = 6.0;
  // false: a flat mid-grey background (fast; for benchmarks and tests).
  bool clutter = true;
};

// A width x height RGB background.
ImageU8 MakeBackground(int width, int height, const BackgroundOptions& options,
                       std::mt19937_64& rng);

}  // namespace handlabel
