#pragma once
// Two sample sources as one: sample i comes from `first` with probability `first_share`
// (decided by (seed, i) alone), else from `second`, and keeps its index, so each
// source's own determinism holds and Sample(i) is the same on every call. Used to mix a
// capture's labelled frames with synthetic ones (docs/training.md).

#include <cstdint>
#include <string>

#include "network/poem/training_sample.h"

namespace handlabel {

class MixedTrainingSamples : public TrainingSampleSource {
 public:
  // Both sources must outlive this object and agree on views and crop size; throws
  // InputError naming the field otherwise, or for a share outside 0..1.
  MixedTrainingSamples(const TrainingSampleSource& first,
                       const TrainingSampleSource& second, double first_share,
                       uint64_t seed);
  int num_views() const override { return first_.num_views(); }
  int crop_size() const override { return first_.crop_size(); }
  TrainingSample Sample(int64_t index) const override;
  // Whether sample `index` comes from `first`.
  bool FromFirst(int64_t index) const;

 private:
  const TrainingSampleSource& first_;
  const TrainingSampleSource& second_;
  double first_share_;
  uint64_t seed_;
};

}  // namespace handlabel
