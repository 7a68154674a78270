#pragma once
// The per-view augmentation of POEM training crops, shared by the synthetic samples
// (training_samples.h) and the samples cut from labelled captures
// (capture_training_samples.h): the random draws of one view and what they do to a
// crop's pixels. Crops here are channel-major 3 x S x S floats of raw levels 0..255
// (before the network's normalisation), so the same draws give the same pixels
// whichever source made the crop.

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace handlabel {

struct TrainingAugmentOptions {
  bool enabled = true;                // false: plain crops (validation, evaluation)
  double scale_sigma = 0.06;          // relative crop size jitter (>= 0)
  double rotation_probability = 0.5;  // chance of an in-plane rotation (0..1)
  double rotation_sigma_deg = 5.0;    // its standard deviation, degrees (>= 0)
  double gain_min = 0.7;              // per-channel colour gain range (0 < min <= max)
  double gain_max = 1.3;
  double noise_rect_probability = 0.2;  // chance of one noise rectangle per view (0..1)
  double noise_rect_max_side = 0.4;     // its largest side, fraction of the crop (0..1]
  void Check(const std::string& source) const;
};

// The random choices of one view's augmentation (identity when disabled).
struct ViewAugmentation {
  double scale = 1.0;
  double rotation_rad = 0.0;
  std::array<double, 3> gain = {1.0, 1.0, 1.0};
  bool noise_rect = false;
  int rect_x0 = 0, rect_y0 = 0, rect_x1 = 0, rect_y1 = 0;  // half-open, crop pixels
  uint64_t noise_seed = 0;
};
ViewAugmentation DrawViewAugmentation(const TrainingAugmentOptions& options,
                                      int crop_size, std::mt19937_64& rng);

// Multiplies each channel of a 3 x S x S crop of levels 0..255 by its gain (capped at
// 255) and fills the noise rectangle, if drawn, with uniform noise in 0..255.
void ApplyGainAndNoiseRect(const ViewAugmentation& augmentation, int crop_size,
                           std::vector<float>* levels);

// Adds Gaussian noise of `sigma` levels to every value and clamps to 0..255 (a sensor's
// read noise; sigma <= 0 adds none).
void AddPixelNoise(double sigma, std::mt19937_64& rng, std::vector<float>* levels);

// The network's input from levels 0..255 and back: value / 255 - 0.5
// (network/poem/training_sample.h; HandCropOptions' default mean and std).
void NormaliseCropLevels(std::vector<float>* levels);
void CropLevelsFromNormalised(std::vector<float>* pixels);

}  // namespace handlabel
