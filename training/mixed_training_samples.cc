#include "training/mixed_training_samples.h"

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"

namespace handlabel {
namespace {

constexpr uint64_t kMixStream = 0x3170;

}  // namespace

MixedTrainingSamples::MixedTrainingSamples(const TrainingSampleSource& first,
                                           const TrainingSampleSource& second,
                                           double first_share, uint64_t seed)
    : first_(first), second_(second), first_share_(first_share), seed_(seed) {
  const std::string source = "mixed training samples";
  RequireInRange(source, "first_share", first_share, 0, 1);
  if (first.num_views() != second.num_views() ||
      first.crop_size() != second.crop_size()) {
    throw InputError(source, "views and crop size",
                     "the same in both sources: " + std::to_string(first.num_views()) +
                         " views of " + std::to_string(first.crop_size()) + " px",
                     std::to_string(second.num_views()) + " views of " +
                         std::to_string(second.crop_size()) + " px");
  }
}

bool MixedTrainingSamples::FromFirst(int64_t index) const {
  // The top 53 bits of the mixed seed as a uniform number in [0, 1).
  const uint64_t bits = MixSeed(seed_, static_cast<uint64_t>(index), kMixStream);
  return static_cast<double>(bits >> 11) * 0x1.0p-53 < first_share_;
}

TrainingSample MixedTrainingSamples::Sample(int64_t index) const {
  return FromFirst(index) ? first_.Sample(index) : second_.Sample(index);
}

}  // namespace handlabel
