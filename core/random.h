#pragma once
// Seed mixing: the one place where handlabel turns (seed, frame, purpose) into the seed
// of a random stream; and the single draws the synthetic generators take from one.
// SplitMix64 (Steele, Lea, Flood 2014) spreads neighbouring inputs over unrelated 64-bit
// values, so seed 1 and seed 2, or frame 7 and frame 8, give unrelated streams. Labels,
// synthetic captures and training depend on these exact values: changing a formula here
// changes every output (tests/core/random_test.cc pins them).

#include <cstdint>
#include <random>
#include <string_view>

namespace handlabel {

// SplitMix64's increment (2^64 / golden ratio).
inline constexpr uint64_t kSplitMix64Gamma = 0x9e3779b97f4a7c15ull;

// SplitMix64's output function on a state value: a bijective 64-bit mixer.
uint64_t SplitMix64Finalize(uint64_t z);

// One SplitMix64 step from state x: SplitMix64Finalize(x + kSplitMix64Gamma).
uint64_t SplitMix64(uint64_t x);

// Seed of the random stream for one purpose (`stream`) of one frame.
uint64_t MixSeed(uint64_t seed, uint64_t frame, uint64_t stream);

// 64-bit FNV-1a of the bytes of `text`: a string hash that is the same on every
// compiler and platform (std::hash is not). The offset basis is 1469598103934665603,
// FNV's standard 14695981039346656037 without its last digit, as the frame seeds have
// always used; kept, since every label's seed depends on it.
uint64_t Fnv1a64(std::string_view text);

// One draw uniform in [lo, hi) from `rng`. A fresh distribution per draw, so that each
// draw takes the same engine values whatever came before: the synthetic captures' seeds
// depend on exactly this sequence of calls.
inline double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// One draw from N(0, sigma^2). A fresh distribution per draw also drops the second
// value of the pair the standard library's method makes, as the seeds expect.
inline double Gaussian(std::mt19937_64& rng, double sigma) {
  return std::normal_distribution<double>(0.0, sigma)(rng);
}

}  // namespace handlabel
