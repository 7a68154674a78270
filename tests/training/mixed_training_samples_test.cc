#include "training/mixed_training_samples.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// A source whose samples say where they come from (frame = marker) and which index
// they were made for.
class MarkedSource : public TrainingSampleSource {
 public:
  MarkedSource(int64_t marker, int views) : marker_(marker), views_(views) {}
  int num_views() const override { return views_; }
  int crop_size() const override { return 64; }
  TrainingSample Sample(int64_t index) const override {
    TrainingSample s;
    s.index = index;
    s.frame = marker_;
    return s;
  }

 private:
  int64_t marker_;
  int views_;
};

TEST(MixedTrainingSamples, ShareDecidesTheSourceByIndexAlone) {
  const MarkedSource real(1, 8), synth(2, 8);
  const MixedTrainingSamples mixed(real, synth, 0.3, 7);
  const MixedTrainingSamples again(real, synth, 0.3, 7);
  int from_real = 0;
  const int n = 4000;
  for (int64_t i = 0; i < n; ++i) {
    const TrainingSample s = mixed.Sample(i);
    EXPECT_EQ(s.index, i);  // each source sees the index itself
    EXPECT_EQ(s.frame, mixed.FromFirst(i) ? 1 : 2);
    EXPECT_EQ(again.FromFirst(i), mixed.FromFirst(i));
    from_real += s.frame == 1;
  }
  // Binomial(4000, 0.3): standard deviation 29 samples; 5 of them either side.
  EXPECT_NEAR(from_real, 0.3 * n, 145);
  const MixedTrainingSamples all_real(real, synth, 1.0, 7);
  for (int64_t i = 0; i < 200; ++i) EXPECT_TRUE(all_real.FromFirst(i));
}

TEST(MixedTrainingSamples, SourcesMustAgreeAndTheShareBeAFraction) {
  const MarkedSource eight(1, 8), five(2, 5);
  EXPECT_THAT(testing::InputErrorOf([&] { MixedTrainingSamples(eight, five, 0.5, 1); }),
              HasSubstr("views"));
  EXPECT_THAT(testing::InputErrorOf([&] { MixedTrainingSamples(eight, eight, 1.5, 1); }),
              HasSubstr("first_share"));
}

}  // namespace
}  // namespace handlabel
