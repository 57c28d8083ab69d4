// Blue noise along the curve (docs/ALGORITHM.md, "Blue noise"): a
// stratum-constrained relaxation of the jittered set. Sample k keeps its
// stratum, the mass interval [k/N, (k+1)/N) S_M of the curve, so the count,
// the curve order and the density (one sample per stratum) stay those of the
// jittered set; only its place inside the stratum, q_k = (k + h_k) / N, moves
// so that no two samples are closer in 3D than rho times the local spacing of
// a hexagonal packing.
//
// Method. Start from the jittered q_k. In Jacobi sweeps by colour (even k,
// then odd k), every sample of the colour that is too close to a neighbour
// tries m candidates stratified over its stratum, h_j = (j + hash(seed,
// sweep, k, j)) / m, in a hashed order, and takes the first whose point
// clears every other sample; if none of them
// does, the least crowded one, when it is less crowded than its place
// (candidates where the density differs from the density at the sample's
// jittered place by more than 1.25x are not taken: across a density step a
// sample would drift to the sparse side, where it is less crowded). Two
// samples closer than twice the larger of their spacings whose densities
// differ by more than that both keep their jittered places (relaxed samples
// gather against a density step, as hard disks against a wall, and the
// strips beside it would no longer hold their share). All samples of a
// colour decide on the points as they were when the colour's half-sweep
// began, so the result depends neither on the order they are visited in nor
// on threads; of two samples of one colour that are too close to each other
// only the one of higher priority (a hash of seed, sweep and index) moves,
// so the two do not jump into each other again.
// Too close: |p_k - p_l| < rho min(d_k, d_l), with d_k = sqrt(2 a_k / sqrt 3)
// the nearest-neighbour distance of a hexagonal packing with a_k = S_M /
// (N delta(p_k)) of area per sample (delta the density at the jittered
// point; d_k at most 8 times the median). Neighbours come from a hash grid
// of 3D cells. This is dart throwing (Cook 1986; Dunbar and Humphreys 2006
// for the grid) restricted to strata, which keeps the stratification of
// Steigleder and McCool's curve sampling; Jacobi colouring as in parallel
// Poisson-disk sampling (Wei 2008).
//
// Where the surface is thinner than the spacing, a sample with
// kMostNeighbours neighbours within its radius keeps its place, and a
// stratum whose candidates span too many grid cells checks them one by one
// (blue_relaxation.cc), so memory stays O(N) on any surface, and the
// half-sweeps' time too (the density-step pass before them visits every
// sample within two spacings, which a surface folded onto itself may crowd).
//
// The set is computed whole (O(N) time, kBlueNoiseBytesPerSample), so a shard,
// index range or region of a blue set costs the whole set's relaxation and
// gives its exact bytes.
//
// Thread-safety: RelaxBlueNoise is reentrant; `place` is called from several
// threads at once when threads > 1.
#ifndef SFCSAMPLER_CORE_BLUE_RELAXATION_H_
#define SFCSAMPLER_CORE_BLUE_RELAXATION_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/vec3.h"

namespace sfc {

// Working memory of a relaxation, bytes a sample (at most, at its peak).
inline constexpr uint64_t kBlueNoiseBytesPerSample = 128;

struct BlueNoiseOptions {
  // The separation asked for, as a share of the local hexagonal spacing; in
  // (0, 0.9] (dart throwing saturates near 0.9 of the hexagonal spacing).
  double rho = 0.78;
  int sweeps = 16;  // Jacobi sweeps (each: even samples, then odd), >= 1
  // Candidates a crowded sample tries in sweep s: min(candidates,
  // first_candidates 2^s), each >= 1.
  int first_candidates = 8;
  int candidates = 64;
  // Asked whether the caller still wants the set (client gone, deadline
  // passed): before every half-sweep and every block of candidates, and
  // every few thousand samples of the O(N) passes, so at most some tens of
  // milliseconds of work pass between two asks. A non-OK status stops the
  // relaxation, which returns it (and frees its memory). Called from several
  // threads at once when threads > 1. Empty: never stop. It does not change
  // the set.
  std::function<absl::Status()> check;
};

// Places mass coordinates: q[i], i < n, non-decreasing in [0, 1], to their
// points p[i] on the surface and, when `density` is not null, the density
// delta there. Must be thread-safe and a pure function of q[i].
using MassPlacer = std::function<absl::Status(const double* q, size_t n, Vec3* p, double* density)>;

struct BlueNoiseSet {
  std::shared_ptr<const std::vector<double>> q;  // q_k, k < count, in [k/N, (k+1)/N]
  uint64_t moved = 0;                            // samples that left their jittered place
  uint64_t unresolved = 0;  // samples still too close to a neighbour at the end
};

// The blue-noise set of `count` samples of `seed` on a curve of total mass
// `total_mass` (S_M), placed by `place`. A pure function of its arguments
// (not of `threads`). Errors: place's; options.check's; INVALID_ARGUMENT for
// options out of range or a non-finite point or density.
absl::StatusOr<BlueNoiseSet> RelaxBlueNoise(uint64_t count, uint64_t seed, double total_mass,
                                            const MassPlacer& place, int threads = 1,
                                            const BlueNoiseOptions& options = {});

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_BLUE_RELAXATION_H_
