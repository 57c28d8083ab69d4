// Which 1D sequence a request places along the curve (paper Sect. 4), and
// its name. A value type with no sampling code (see core/types/tree_options.h).
#ifndef SFCSAMPLER_CORE_TYPES_SEQUENCE_KIND_H_
#define SFCSAMPLER_CORE_TYPES_SEQUENCE_KIND_H_

#include <cstdint>
#include <optional>
#include <string_view>

namespace sfc {

enum class SequenceKind {
  kJittered,      // q_k = (k + U_k) / N: the paper's method of choice (default)
  kEqual,         // q_k = (k + 1/2) / N
  kRandom,        // q_k = U'_k, independent uniforms
  kVanDerCorput,  // q_k = base-2 radical inverse of k
  kProgressive,   // Owen-scrambled base-2 radical inverse: every prefix of
                  // length 2^m puts exactly one q in each [j/2^m, (j+1)/2^m)
  kBlue,          // q_k = (k + h_k) / N, h_k in [0, 1) chosen by a relaxation of
                  // the whole set so that samples keep apart in 3D (blue noise;
                  // core/blue_relaxation.h)
  kSobol,         // an Owen-scrambled 2D Sobol (0,2)-sequence in the unit
                  // square, warped through the tree onto the surface
                  // (core/tree_warp.h); q_k is its first coordinate
};

std::string_view SequenceName(SequenceKind kind);  // "jittered", "equal", ...
std::optional<SequenceKind> SequenceFromName(std::string_view name);

// Whether q_k grows with k (jittered, equal, blue): such a sequence is in curve
// order as it is; the others are sorted per request.
inline bool SequenceIsMonotone(SequenceKind kind) {
  return kind == SequenceKind::kJittered || kind == SequenceKind::kEqual ||
         kind == SequenceKind::kBlue;
}

// Whether a sample is a point of the unit square warped onto the surface
// (sobol) rather than a mass coordinate along the curve. Such a set is sorted
// whole into curve order, and index ranges and shards select positions in
// that order (docs/SERVICE.md, "Sobol sets").
inline bool SequenceIsTwoDimensional(SequenceKind kind) { return kind == SequenceKind::kSobol; }

// The largest count the kind serves: 2^32 for the radical-inverse kinds (van
// der Corput, progressive, sobol), whose 32 digits of k index a sample (and a
// sobol address holds k in 32 bits, core/curve_samples.h); no bound for the
// others.
inline uint64_t MaxSequenceCount(SequenceKind kind) {
  const bool radical_inverse = kind == SequenceKind::kVanDerCorput ||
                               kind == SequenceKind::kProgressive || kind == SequenceKind::kSobol;
  return radical_inverse ? uint64_t{1} << 32 : UINT64_MAX;
}

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_TYPES_SEQUENCE_KIND_H_
