#include "training/view_augmentation.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void TrainingAugmentOptions::Check(const std::string& source) const {
  RequireInRange(source, "scale_sigma", scale_sigma, 0, 0.4);
  RequireInRange(source, "rotation_probability", rotation_probability, 0, 1);
  RequireInRange(source, "rotation_sigma_deg", rotation_sigma_deg, 0, 90);
  if (!(gain_min > 0 && gain_max >= gain_min)) {
    throw InputError(source, "gain_min/gain_max", "0 < gain_min <= gain_max",
                     OptionValueText(gain_min) + "/" + OptionValueText(gain_max));
  }
  RequireInRange(source, "noise_rect_probability", noise_rect_probability, 0, 1);
  RequireInRange(source, "noise_rect_max_side", noise_rect_max_side, 0.01, 1);
}

ViewAugmentation DrawViewAugmentation(const TrainingAugmentOptions& o, int crop_size,
                                      std::mt19937_64& rng) {
  ViewAugmentation a;
  if (!o.enabled) return a;
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  a.scale = 1.0 + o.scale_sigma * std::clamp(normal(rng), -2.0, 2.0);
  const bool rotate = unit(rng) < o.rotation_probability;
  const double angle = o.rotation_sigma_deg * M_PI / 180.0 * normal(rng);
  if (rotate) a.rotation_rad = angle;
  for (double& g : a.gain) g = o.gain_min + (o.gain_max - o.gain_min) * unit(rng);
  a.noise_rect = unit(rng) < o.noise_rect_probability;
  const double max_side = o.noise_rect_max_side * crop_size;
  const int w = std::max(1, static_cast<int>(std::lround(max_side * unit(rng))));
  const int h = std::max(1, static_cast<int>(std::lround(max_side * unit(rng))));
  a.rect_x0 = static_cast<int>(unit(rng) * (crop_size - w + 1));
  a.rect_y0 = static_cast<int>(unit(rng) * (crop_size - h + 1));
  a.rect_x1 = a.rect_x0 + w;
  a.rect_y1 = a.rect_y0 + h;
  a.noise_seed = rng();
  if (!a.noise_rect) a.rect_x0 = a.rect_y0 = a.rect_x1 = a.rect_y1 = 0;
  return a;
}

void ApplyGainAndNoiseRect(const ViewAugmentation& aug, int S,
                           std::vector<float>* levels) {
  HL_CHECK(levels->size() == 3u * S * S, "a 3 x S x S crop");
  // Pixel by pixel, channels innermost: the noise draws keep this order.
  std::mt19937_64 noise_rng(aug.noise_seed);
  std::uniform_real_distribution<float> noise(0.0f, 255.0f);
  for (int y = 0; y < S; ++y) {
    for (int x = 0; x < S; ++x) {
      const bool in_rect = aug.noise_rect && x >= aug.rect_x0 && x < aug.rect_x1 &&
                           y >= aug.rect_y0 && y < aug.rect_y1;
      for (int ch = 0; ch < 3; ++ch) {
        float& v = (*levels)[(ch * S + y) * S + x];
        v = std::min(255.0f, static_cast<float>(v * aug.gain[ch]));
        if (in_rect) v = noise(noise_rng);
      }
    }
  }
}

void AddPixelNoise(double sigma, std::mt19937_64& rng, std::vector<float>* levels) {
  if (!(sigma > 0)) return;
  std::normal_distribution<float> gauss(0.0f, static_cast<float>(sigma));
  for (float& v : *levels) v = std::clamp(v + gauss(rng), 0.0f, 255.0f);
}

void NormaliseCropLevels(std::vector<float>* levels) {
  for (float& v : *levels) v = v / 255.0f - 0.5f;
}

void CropLevelsFromNormalised(std::vector<float>* pixels) {
  for (float& v : *pixels) v = (v + 0.5f) * 255.0f;
}

}  // namespace handlabel
