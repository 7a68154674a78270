#include "core/random.h"

#include <gtest/gtest.h>

#include <string>

namespace handlabel {
namespace {

// The formulas as they were written out before core/random existed (network/
// poem_trainer.cc Mix, capture/synth_capture.cc SplitMix64 and MixSeed, pipeline/
// label_policy.cc FrameSeed): the shared module must give the same bits.
uint64_t OldSplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t OldMixSeed(uint64_t seed, uint64_t frame, uint64_t stream) {
  return OldSplitMix64(OldSplitMix64(OldSplitMix64(seed) ^ frame) ^ stream);
}

uint64_t OldFrameSeed(uint64_t job_seed, const std::string& frame) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : frame) h = (h ^ c) * 1099511628211ull;
  uint64_t z = job_seed + 0x9e3779b97f4a7c15ull * (h | 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

TEST(Random, SplitMix64MatchesTheOldFormulaAndKnownValues) {
  for (uint64_t x : {0ull, 1ull, 2ull, 42ull, 0xffffffffffffffffull, 1234567890123ull}) {
    EXPECT_EQ(SplitMix64(x), OldSplitMix64(x)) << x;
  }
  // The reference SplitMix64 generator seeded with 0 starts with these outputs.
  EXPECT_EQ(SplitMix64(0), 0xe220a8397b1dcdafull);
  EXPECT_EQ(SplitMix64(kSplitMix64Gamma), 0x6e789e6aa1b965f4ull);
}

TEST(Random, MixSeedMatchesTheOldFormula) {
  for (uint64_t seed : {0ull, 7ull, 4242ull}) {
    for (uint64_t frame : {0ull, 1ull, 999ull}) {
      for (uint64_t stream : {1ull, 2ull, 3ull, 2ull + 16 * 5}) {
        EXPECT_EQ(MixSeed(seed, frame, stream), OldMixSeed(seed, frame, stream));
      }
    }
  }
  // The trainer's per-step seed Mix(seed ^ Mix(step)).
  EXPECT_EQ(SplitMix64(4242 ^ SplitMix64(17)), OldSplitMix64(4242 ^ OldSplitMix64(17)));
}

TEST(Random, FrameSeedPartsMatchTheOldFormula) {
  for (const std::string frame : {"", "000000", "000001", "seq/cam_a/17"}) {
    for (uint64_t job_seed : {0ull, 1ull, 20260101ull}) {
      EXPECT_EQ(SplitMix64Finalize(job_seed + kSplitMix64Gamma * (Fnv1a64(frame) | 1)),
                OldFrameSeed(job_seed, frame))
          << frame;
    }
  }
  // The project's offset basis (not FNV's standard 14695981039346656037: see
  // core/random.h), then one FNV-1a step.
  EXPECT_EQ(Fnv1a64(""), 1469598103934665603ull);
  EXPECT_EQ(Fnv1a64("a"), 0x44bd8ad473cd9906ull);
}

// The synthetic generators' draws as each file wrote them before core/random had them:
// a fresh distribution per draw, so a Gaussian's unused second value is dropped.
TEST(Random, DrawsMatchTheOldFreshDistributionPerDraw) {
  std::mt19937_64 shared(7), old(7);
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(Uniform(shared, -0.3, 2.5),
              std::uniform_real_distribution<double>(-0.3, 2.5)(old));
    EXPECT_EQ(Gaussian(shared, 0.2), std::normal_distribution<double>(0.0, 0.2)(old));
  }
  EXPECT_EQ(shared(), old());
}

}  // namespace
}  // namespace handlabel
