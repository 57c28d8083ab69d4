// Counter-based random numbers: a pure function of (seed, stream, counter).
//
// docs/ALGORITHM.md "Random access": jitter U_k is a hash of (seed, k), so any
// sample can be computed alone. The mixer is SplitMix64's finaliser (Steele,
// Lea and Flood 2014), applied twice. Stateless and thread-safe.
#ifndef SFCSAMPLER_BASE_COUNTER_HASH_H_
#define SFCSAMPLER_BASE_COUNTER_HASH_H_

#include <cstdint>

namespace sfc {

// U is uint64_t, or a vector of them (GCC's vector extensions) hashed lane
// by lane with the same bits.
template <typename U>
inline U Mix64(U z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The streams of the sampler's random numbers, one per use, so no two uses
// share bits (core/sequence.cc, core/blue_relaxation.cc). A new use takes a
// new number: changing one changes the bytes of its sequence.
namespace hash_stream {
inline constexpr uint64_t kJitter = 1;
inline constexpr uint64_t kRandom = 2;
inline constexpr uint64_t kOwen = 3;                    // the progressive scramble
inline constexpr uint64_t kOwenTail = 4;                // and its bits below 2^-32
inline constexpr uint64_t kSobol[2] = {5, 6};           // the sobol coordinates' scrambles
inline constexpr uint64_t kSobolTail[2] = {7, 8};       // and their bits below 2^-32
inline constexpr uint64_t kBlueCandidate = 0x626c7565;  // "blue" in ASCII
inline constexpr uint64_t kBluePriority = 0x626c7566;
inline constexpr uint64_t kBlueOrder = 0x626c7567;  // the order a sample tries its candidates in
}  // namespace hash_stream

// The key of the stream `stream` of `seed`.
inline uint64_t CounterKey(uint64_t seed, uint64_t stream) {
  return Mix64(seed + 0x9e3779b97f4a7c15ULL * (stream + 1));
}

// CounterHash's two halves, for a caller that hashes one counter in several
// streams: the counter's own mix, then with a stream's key.
template <typename U>
inline U CounterMix(U counter) {
  return Mix64(counter + 0x632be59bd9b4e019ULL);
}
template <typename U>
inline U KeyedHash(uint64_t key, U counter_mix) {
  return Mix64(key ^ counter_mix);
}

// 64 well-mixed bits for `counter` in the stream `stream` of `seed`.
inline uint64_t CounterHash(uint64_t seed, uint64_t stream, uint64_t counter) {
  return KeyedHash(CounterKey(seed, stream), CounterMix(counter));
}

// The double uniform in [0,1) of 53 of a hash's bits (CounterUniform's).
inline double UniformOf(uint64_t hash) { return static_cast<double>(hash >> 11) * 0x1.0p-53; }

// A double uniform in [0,1) with 53 random bits.
inline double CounterUniform(uint64_t seed, uint64_t stream, uint64_t counter) {
  return UniformOf(CounterHash(seed, stream, counter));
}

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_COUNTER_HASH_H_
