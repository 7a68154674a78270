#include "network/poem/mask_sheet.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "image/mask_outline.h"

namespace handlabel {

ImageU8 MakeMaskSheet(const std::vector<TrainingSample>& samples,
                      const std::vector<PoemPrediction>& predictions) {
  HL_CHECK(samples.size() == predictions.size(), "one prediction per sample");
  if (samples.empty()) throw InputError("mask sheet", "samples", "at least one", "none");
  const int views = static_cast<int>(samples[0].views.size());
  const int S = static_cast<int>(std::lround(std::sqrt(samples[0].views[0].mask.size())));
  if (S == 0) throw InputError("mask sheet", "samples", "crop masks", "none");
  constexpr int kGap = 2;
  ImageU8 sheet(views * (S + kGap) - kGap,
                static_cast<int>(samples.size()) * (S + kGap) - kGap, 3, 255);
  for (size_t row = 0; row < samples.size(); ++row) {
    if (predictions[row].masks.size() != samples[row].views.size()) {
      throw InputError("mask sheet", "predictions", "mask-head probabilities per view",
                       "none (the network has no mask head)");
    }
    for (int v = 0; v < views; ++v) {
      const TrainingView& view = samples[row].views[v];
      const std::vector<float>& prob = predictions[row].masks[v];
      const int M = static_cast<int>(std::lround(std::sqrt(prob.size())));
      const int cell = S / M;
      auto truth = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < S && y < S && view.mask[y * S + x] > 0.5f;
      };
      const int x0 = v * (S + kGap), y0 = static_cast<int>(row) * (S + kGap);
      for (int y = 0; y < S; ++y) {
        for (int x = 0; x < S; ++x) {
          double rgb[3];
          for (int c = 0; c < 3; ++c) {
            // The network's input is RGB / 255 - 0.5.
            rgb[c] =
                std::clamp((view.image[(c * S + y) * S + x] + 0.5) * 255.0, 0.0, 255.0);
          }
          if (prob[(y / cell) * M + x / cell] > 0.5f) {
            rgb[0] = 0.5 * rgb[0] + 127.5;
            rgb[1] *= 0.5;
            rgb[2] *= 0.5;
          }
          if (OnMaskOutline(truth, x, y)) rgb[0] = 0, rgb[1] = 255, rgb[2] = 0;
          for (int c = 0; c < 3; ++c)
            sheet.at(x0 + x, y0 + y, c) = static_cast<uint8_t>(std::lround(rgb[c]));
        }
      }
    }
  }
  return sheet;
}

}  // namespace handlabel
