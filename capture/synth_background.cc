#include "capture/synth_background.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/random.h"

namespace handlabel {
namespace {

Eigen::Vector3f RandomColor(std::mt19937_64& rng) {
  return Eigen::Vector3f(Uniform(rng, 0, 1), Uniform(rng, 0, 1), Uniform(rng, 0, 1));
}

void Put(ImageU8* img, int x, int y, const Eigen::Vector3f& c) {
  for (int k = 0; k < 3; ++k) {
    img->at(x, y, k) = static_cast<uint8_t>(std::clamp(c[k] * 255.0f, 0.0f, 255.0f));
  }
}

// The base: a flat colour, a linear gradient along a random direction, or smooth value
// noise (bilinear interpolation of a coarse random grid), from colour a to b.
void FillBase(const Eigen::Vector3f& a, const Eigen::Vector3f& b, std::mt19937_64& rng,
              ImageU8* img) {
  const int width = img->width, height = img->height;
  const int base = static_cast<int>(Uniform(rng, 0, 3));
  if (base == 0) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) Put(img, x, y, a);
  } else if (base == 1) {  // linear gradient along a random direction
    const double angle = Uniform(rng, 0, 6.2832);
    const double dx = std::cos(angle), dy = std::sin(angle);
    const double span = std::abs(dx) * width + std::abs(dy) * height;
    const double offset = std::min(0.0, dx * width) + std::min(0.0, dy * height);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float t = static_cast<float>((dx * x + dy * y - offset) / span);
        Put(img, x, y, (1 - t) * a + t * b);
      }
    }
  } else {  // smooth value noise: bilinear interpolation of a coarse random grid
    const int cell = std::max(8, static_cast<int>(Uniform(rng, 0.05, 0.25) * width));
    const int gw = width / cell + 2, gh = height / cell + 2;
    std::vector<float> grid(gw * gh);
    for (float& g : grid) g = static_cast<float>(Uniform(rng, 0, 1));
    for (int y = 0; y < height; ++y) {
      const int gy = y / cell;
      const float fy = static_cast<float>(y % cell) / cell;
      for (int x = 0; x < width; ++x) {
        const int gx = x / cell;
        const float fx = static_cast<float>(x % cell) / cell;
        const float t =
            (1 - fy) * ((1 - fx) * grid[gy * gw + gx] + fx * grid[gy * gw + gx + 1]) +
            fy *
                ((1 - fx) * grid[(gy + 1) * gw + gx] + fx * grid[(gy + 1) * gw + gx + 1]);
        Put(img, x, y, (1 - t) * a + t * b);
      }
    }
  }
}

// Half the time, a texture band: stripes or checker over part of the image.
void MaybeDrawTextureBand(std::mt19937_64& rng, ImageU8* img) {
  const int width = img->width, height = img->height;
  if (!(Uniform(rng, 0, 1) < 0.5)) return;
  const int period = std::max(2, static_cast<int>(Uniform(rng, 0.01, 0.06) * width));
  const bool checker = Uniform(rng, 0, 1) < 0.5;
  const Eigen::Vector3f c = RandomColor(rng);
  const int x0 = static_cast<int>(Uniform(rng, 0, width)),
            y0 = static_cast<int>(Uniform(rng, 0, height));
  const int x1 = std::min(width, x0 + static_cast<int>(Uniform(rng, 0.2, 0.8) * width));
  const int y1 = std::min(height, y0 + static_cast<int>(Uniform(rng, 0.2, 0.8) * height));
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const bool on =
          checker ? ((x / period) + (y / period)) % 2 == 0 : (x / period) % 2 == 0;
      if (on) Put(img, x, y, c);
    }
  }
}

// Clutter: up to max_shapes rectangles and ellipses of random colours.
void DrawClutterShapes(int max_shapes, std::mt19937_64& rng, ImageU8* img) {
  const int width = img->width, height = img->height;
  const int shapes = static_cast<int>(Uniform(rng, 0, max_shapes + 1));
  for (int s = 0; s < shapes; ++s) {
    const Eigen::Vector3f c = RandomColor(rng);
    const double cx = Uniform(rng, 0, width), cy = Uniform(rng, 0, height);
    const double rx = Uniform(rng, 0.02, 0.2) * width,
                 ry = Uniform(rng, 0.02, 0.2) * height;
    const bool ellipse = Uniform(rng, 0, 1) < 0.5;
    const int xa = std::max(0, static_cast<int>(cx - rx)),
              xb = std::min(width - 1, static_cast<int>(cx + rx));
    const int ya = std::max(0, static_cast<int>(cy - ry)),
              yb = std::min(height - 1, static_cast<int>(cy + ry));
    for (int y = ya; y <= yb; ++y) {
      for (int x = xa; x <= xb; ++x) {
        if (ellipse) {
          const double u = (x - cx) / rx, v = (y - cy) / ry;
          if (u * u + v * v > 1) continue;
        }
        Put(img, x, y, c);
      }
    }
  }
}

// Sensor-like noise: triangular (sum of two uniforms, standard deviation `sigma`)
// from a xorshift generator, ~50x cheaper than std::normal_distribution per pixel.
void AddSensorNoise(double max_noise, std::mt19937_64& rng, ImageU8* img) {
  const double sigma = Uniform(rng, 0, max_noise);
  if (!(sigma > 0.5)) return;
  uint64_t state = rng() | 1;
  // Sum of two uniforms on [-a, a] has standard deviation a * sqrt(2/3).
  const float a = static_cast<float>(sigma / std::sqrt(2.0 / 3.0)) / 32768.0f;
  for (uint8_t& v : img->data) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    const int u1 = static_cast<int>(state & 0xffff) - 32768;
    const int u2 = static_cast<int>((state >> 16) & 0xffff) - 32768;
    const float n = a * static_cast<float>(u1 + u2);
    v = static_cast<uint8_t>(std::clamp(v + n, 0.0f, 255.0f));
  }
}

}  // namespace

ImageU8 MakeBackground(int width, int height, const BackgroundOptions& options,
                       std::mt19937_64& rng) {
  ImageU8 img(width, height, 3, 128);
  if (!options.clutter) return img;
  const Eigen::Vector3f a = RandomColor(rng), b = RandomColor(rng);
  FillBase(a, b, rng, &img);
  MaybeDrawTextureBand(rng, &img);
  DrawClutterShapes(options.max_shapes, rng, &img);
  AddSensorNoise(options.max_noise, rng, &img);
  return img;
}

}  // namespace handlabel
