#include "network/poem/training_sample.h"

#include <cmath>

#include "core/errors.h"

namespace handlabel {

void MaskIouCounts::Add(const std::vector<float>& probability,
                        const std::vector<float>& crop_mask) {
  const int M = static_cast<int>(std::lround(std::sqrt(double(probability.size()))));
  const int S = 4 * M;
  HL_CHECK(static_cast<int>(probability.size()) == M * M &&
               static_cast<int>(crop_mask.size()) == S * S,
           "mask IoU: an M x M prediction and a 4M x 4M crop mask");
  for (int i = 0; i < M; ++i) {
    for (int j = 0; j < M; ++j) {
      double coverage = 0;
      for (int y = 4 * i; y < 4 * i + 4; ++y)
        for (int x = 4 * j; x < 4 * j + 4; ++x) coverage += crop_mask[y * S + x];
      const bool truth = coverage / 16.0 > 0.5;
      const bool predicted = probability[i * M + j] > 0.5f;
      intersection += truth && predicted;
      union_cells += truth || predicted;
    }
  }
}

bool MaskIouCounts::Add(const PoemPrediction& prediction, const TrainingSample& sample) {
  bool added = false;
  for (size_t v = 0; v < prediction.masks.size() && v < sample.views.size(); ++v) {
    if (prediction.masks[v].empty() || sample.views[v].mask.empty()) continue;
    Add(prediction.masks[v], sample.views[v].mask);
    added = true;
  }
  return added;
}

std::vector<TrainingSample> SampleRange(const TrainingSampleSource& source, int64_t first,
                                        int64_t end) {
  std::vector<TrainingSample> samples;
  for (int64_t i = first; i < end; ++i) samples.push_back(source.Sample(i));
  return samples;
}

}  // namespace handlabel
