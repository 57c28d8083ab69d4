#include "core/blue_relaxation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "absl/strings/str_format.h"
#include "base/counter_hash.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"
#include "core/hilbert3d.h"
#include "core/sequence.h"

namespace sfc {
namespace {

// A sample's spacing is at most this many times the median spacing (where the
// density vanishes at a point the spacing would be infinite).
constexpr double kMaxSpacingRatio = 8;
// Searching samples are placed and checked in blocks of about this many
// candidates: a block's candidates stay in cache between their placement and
// their check.
constexpr size_t kBlockCandidates = 4096;
// The hash grid's cells are this many median radii (rho times the median
// spacing) a side: a query near a point meets 1 to 8 of them, and a
// candidates' box (a stratum widened by a radius) a few more. 3 took 15 %
// less CPU than 2 for 10^6 sphere samples, 4 no less than 3; the cell size
// changes no decision.
constexpr double kCellRadii = 3;
// A candidate whose density differs from the density at its sample's
// jittered place by more than this factor is not taken.
constexpr double kDensityJump = 1.25;
// Two samples closer than this many times the larger of their spacings whose
// densities differ by more than kDensityJump both keep their jittered places
// (Relaxation::FreezeBesideJumps).
constexpr double kJumpReach = 2;
// The O(N) passes ask options.check every this many samples (a few
// milliseconds of work: placing a sample through a cursor takes about a
// microsecond, a neighbour query less).
constexpr size_t kCheckEvery = 4096;
// A sample with this many neighbours closer than its radius sits where the
// surface is thinner than the spacing (a tube or band narrower than rho
// d_k, where every point of its stratum is that crowded): it keeps its
// place, and the half-sweeps' queries stop counting there.
// A relaxed set has none within the radius, a jittered one a few.
constexpr int kMostNeighbours = 16;
// A stratum whose candidates' box meets more grid cells than this is long
// and thin in 3D: its candidates are checked one by one (AnyNear), not
// against one gather of the box, whose cells could number millions.
constexpr int64_t kMostGatherCells = 4096;

// Points in a grid of cubic cells of side `cell`, hashed by Morton code: a
// bucket array of cell lists in CSR form, each entry a copy of its point and radius (so a
// query reads contiguous memory). An entry can be killed when its point
// moves; the moved points are listed in a second grid.
class HashGrid {
 public:
  static constexpr uint32_t kDead = ~uint32_t{0};
  struct Entry {
    Vec3 p;
    double r;
    uint32_t id;  // kDead: the point has moved
  };

  explicit HashGrid(double cell) : inv_cell_(1 / cell) {}

  // Lists the points ids[i] at p[ids[i]] with radius r[ids[i]]; when `slots`
  // is not null, (*slots)[ids[i]] is set to the point's entry.
  void Build(const std::vector<Vec3>& p, const std::vector<double>& r,
             const std::vector<uint32_t>& ids, std::vector<uint32_t>* slots) {
    size_t buckets = 16;
    while (buckets < 2 * ids.size()) buckets *= 2;
    mask_ = buckets - 1;
    start_.assign(buckets + 1, 0);
    keys_.resize(ids.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      const Vec3& x = p[ids[i]];
      keys_[i] = Bucket(Cell(x.x), Cell(x.y), Cell(x.z));
      ++start_[keys_[i] + 1];
    }
    for (size_t b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
    entries_.resize(ids.size());
    fill_.assign(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < ids.size(); ++i) {
      const uint32_t slot = fill_[keys_[i]]++;
      entries_[slot] = {p[ids[i]], r[ids[i]], ids[i]};
      if (slots) (*slots)[ids[i]] = slot;
    }
  }
  void Kill(uint32_t slot) { entries_[slot].id = kDead; }
  // Lists no point (keeping the memory for the next Build).
  void Clear() { entries_.clear(); }
  int64_t Cell(double x) const { return static_cast<int64_t>(std::floor(x * inv_cell_)); }
  // The cell's Morton code, cut to the table: neighbouring cells share
  // cache lines, and so do the cells of queries made in curve order.
  // Morton(cx, cy, cz) = Spread(cx) | Spread(cy) << 1 | Spread(cz) << 2.
  static uint64_t Spread(int64_t c) { return Spread3(static_cast<uint32_t>(c)); }
  uint32_t Bucket(int64_t cx, int64_t cy, int64_t cz) const {
    return static_cast<uint32_t>((Spread(cx) | Spread(cy) << 1 | Spread(cz) << 2) & mask_);
  }
  // Calls f(entry) for every live entry in the bucket of cell (cx, cy, cz)
  // (and of the cells sharing it); stops and returns true when f does.
  template <typename F>
  bool AnyIn(int64_t cx, int64_t cy, int64_t cz, const F& f) const {
    return AnyInMorton(Spread(cx) | Spread(cy) << 1 | Spread(cz) << 2, f);
  }
  // The same for the cell of Morton code `morton`.
  template <typename F>
  bool AnyInMorton(uint64_t morton, const F& f) const {
    if (entries_.empty()) return false;
    const uint32_t b = static_cast<uint32_t>(morton & mask_);
    for (uint32_t t = start_[b]; t < start_[b + 1]; ++t) {
      if (entries_[t].id != kDead && f(entries_[t])) return true;
    }
    return false;
  }

 private:
  double inv_cell_;
  uint64_t mask_ = 0;
  std::vector<uint32_t> start_, keys_, fill_;
  std::vector<Entry> entries_;
};

class Relaxation {
 public:
  Relaxation(uint64_t count, uint64_t seed, const MassPlacer& place, int threads,
             const BlueNoiseOptions& options)
      : n_(count),
        seed_(seed),
        place_(place),
        threads_(std::max(1, threads)),
        options_(options),
        main_(1),
        moved_grid_(1) {}

  absl::StatusOr<BlueNoiseSet> Run(double total_mass);

 private:
  // Calls f(j, (|x - p_j| / t_ij)^2) for the points p_j, j != i, of the
  // grids closer to x than t_ij = rho min(d_i, d_j), x being the place of
  // sample i (its own or a candidate's), until f returns true; returns
  // whether it did.
  template <typename F>
  bool AnyNear(uint32_t i, const Vec3& x, const F& f) const;
  // min(1, min_j (|x - p_j| / t_ij)^2) over the points p_j of `near`, which
  // holds (at least) every point of the grids within r_i of x other than
  // sample i's: 1 when x clears every neighbour. May stop early with any
  // value <= floor once one is found (so the value is the same whatever the
  // order of `near` when it is above floor).
  double Crowding(uint32_t i, const Vec3& x, double floor,
                  const std::vector<HashGrid::Entry>& near) const;
  // The full minimum of Crowding, from the grids directly (a query of the
  // cube of side 2 r_i around x).
  double CrowdingAt(uint32_t i, const Vec3& x) const {
    double worst = 1;
    AnyNear(i, x, [&](uint32_t, double ratio2) {
      worst = std::min(worst, ratio2);
      return false;
    });
    return worst;
  }
  // The number of grid cells Gather(i, lo, hi, ...) visits.
  double GatherCells(uint32_t i, const Vec3& lo, const Vec3& hi) const {
    const double ri = r_[i];
    const auto span = [&](double a, double b) {
      return static_cast<double>(main_.Cell(b + ri) - main_.Cell(a - ri) + 1);
    };
    return span(lo.x, hi.x) * span(lo.y, hi.y) * span(lo.z, hi.z);
  }
  // Fills *near with the live points of the grids, other than sample i's,
  // in the cells that meet the box [lo, hi] widened by r_i on every side
  // (entries outside that box are left out).
  void Gather(uint32_t i, const Vec3& lo, const Vec3& hi, std::vector<HashGrid::Entry>* near) const;
  // Who of two samples of a colour that are too close moves in `sweep`.
  uint64_t Priority(int sweep, uint32_t k) const {
    return CounterHash(seed_, hash_stream::kBluePriority,
                       static_cast<uint64_t>(k) * options_.sweeps + sweep);
  }
  // Marks frozen_ the samples beside a density jump. Relaxed samples layer
  // against a step on both sides, as hard disks against a wall (the dense
  // side's small spacing leaves a sparse-side sample more room there;
  // docs/QUALITY.md, "Strip checks"). A frozen sample stays uniform in its
  // stratum, so a strip beside a step holds its share as in the jittered
  // set; its neighbours relax around it.
  absl::Status FreezeBesideJumps();
  // options_.check's answer (OK when it is empty).
  absl::Status Check() const { return options_.check ? options_.check() : absl::OkStatus(); }
  bool Conflicts(uint32_t i, const Vec3& x) const {
    return AnyNear(i, x, [](uint32_t, double) { return true; });
  }
  // Runs f(part, begin, end) over at most `threads_` contiguous parts of
  // [0, n), in parallel.
  absl::Status ForParts(size_t n, const std::function<absl::Status(int, size_t, size_t)>& f) const;
  // Half-sweep `sweep` of the samples `todo` (one colour): each either clears
  // (suspect_ = 0), moves (new place in q_/p_, listed in *moved: to a place
  // that clears every neighbour or, if none of its candidates does, to the
  // least crowded one) or stays.
  absl::Status HalfSweep(int sweep, const std::vector<uint32_t>& todo,
                         std::vector<uint32_t>* moved);

  const uint64_t n_, seed_;
  const MassPlacer& place_;
  const int threads_;
  const BlueNoiseOptions options_;
  std::vector<double> q_;
  std::vector<Vec3> p_;
  std::vector<double> r_;         // rho d_i
  std::vector<uint8_t> suspect_;  // may be too close to a neighbour
  std::vector<uint8_t> in_todo_;  // in the half-sweep's list (constant during it)
  std::vector<double> delta_;     // the density at each sample's jittered place
  std::vector<uint8_t> frozen_;   // keeps its jittered place (FreezeBesideJumps)
  std::vector<uint8_t> moves_;    // HalfSweep's
  std::vector<double> new_q_;
  std::vector<Vec3> new_p_;
  bool uniform_density_ = true;  // all of delta_ alike: candidates need none
  HashGrid main_, moved_grid_;
};

absl::Status Relaxation::ForParts(size_t n,
                                  const std::function<absl::Status(int, size_t, size_t)>& f) const {
  const int parts = static_cast<int>(std::min<size_t>(threads_, std::max<size_t>(1, n / 1024)));
  if (parts <= 1) return f(0, 0, n);
  std::vector<absl::Status> status(parts);
  WorkerPool::Shared().ParallelFor(
      parts, [&](int t) { status[t] = f(t, n * t / parts, n * (t + 1) / parts); });
  for (const absl::Status& st : status) RETURN_IF_ERROR(st);
  return absl::OkStatus();
}

template <typename F>
bool Relaxation::AnyNear(uint32_t i, const Vec3& x, const F& f) const {
  const double ri = r_[i];
  // Every cell that meets the cube of side 2 r_i around x (one or two a
  // side at the median radius, cells being kCellRadii median radii; more for
  // a radius clamped at kMaxSpacingRatio medians).
  const int64_t x0 = main_.Cell(x.x - ri), x1 = main_.Cell(x.x + ri);
  const int64_t y0 = main_.Cell(x.y - ri), y1 = main_.Cell(x.y + ri);
  const int64_t z0 = main_.Cell(x.z - ri), z1 = main_.Cell(x.z + ri);
  const auto visit = [&](const HashGrid::Entry& e) {
    if (e.id == i) return false;
    const double r = std::min(ri, e.r);
    const Vec3 d = e.p - x;
    const double d2 = Dot(d, d);
    return d2 < r * r && f(e.id, d2 / (r * r));
  };
  // The cells' Morton codes from each coordinate's spread bits, spread once
  // (a query of 2 x 2 x 2 cells of both grids: 6 spreads, not 48).
  constexpr int64_t kKept = 4;
  uint64_t sz[kKept];
  for (int64_t c = z0; c <= std::min(z1, z0 + kKept - 1); ++c)
    sz[c - z0] = HashGrid::Spread(c) << 2;
  for (int64_t a = x0; a <= x1; ++a) {
    const uint64_t sa = HashGrid::Spread(a);
    for (int64_t b = y0; b <= y1; ++b) {
      const uint64_t sab = sa | HashGrid::Spread(b) << 1;
      for (int64_t c = z0; c <= z1; ++c) {
        const uint64_t morton = sab | (c - z0 < kKept ? sz[c - z0] : HashGrid::Spread(c) << 2);
        if (main_.AnyInMorton(morton, visit) || moved_grid_.AnyInMorton(morton, visit)) return true;
      }
    }
  }
  return false;
}

absl::Status Relaxation::FreezeBesideJumps() {
  frozen_.assign(n_, 0);
  if (uniform_density_) return absl::OkStatus();
  // Sample i looks kJumpReach d_i around its point (d_i as clamped in r_);
  // a pair is found from its sparse end in any case.
  // Marked by any thread that finds the sample in a pair (one byte a sample,
  // however many pairs a sample is in).
  std::vector<std::atomic<uint8_t>> beside(n_);
  RETURN_IF_ERROR(ForParts(n_, [&](int, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if ((i - begin) % kCheckEvery == 0) RETURN_IF_ERROR(Check());
      const double reach = kJumpReach * r_[i] / options_.rho;
      const Vec3 x = p_[i];
      bool jump = false;
      const auto visit = [&](const HashGrid::Entry& e) {
        const Vec3 v = e.p - x;
        if (Dot(v, v) < reach * reach &&
            (delta_[e.id] * kDensityJump < delta_[i] || delta_[e.id] > kDensityJump * delta_[i])) {
          beside[e.id].store(1, std::memory_order_relaxed);
          jump = true;
        }
        return false;
      };
      const int64_t x1 = main_.Cell(x.x + reach), y1 = main_.Cell(x.y + reach);
      const int64_t z1 = main_.Cell(x.z + reach);
      for (int64_t a = main_.Cell(x.x - reach); a <= x1; ++a) {
        for (int64_t b = main_.Cell(x.y - reach); b <= y1; ++b) {
          for (int64_t c = main_.Cell(x.z - reach); c <= z1; ++c) main_.AnyIn(a, b, c, visit);
        }
      }
      if (jump) beside[i].store(1, std::memory_order_relaxed);
    }
    return absl::OkStatus();
  }));
  for (uint64_t i = 0; i < n_; ++i) frozen_[i] = beside[i].load(std::memory_order_relaxed);
  return absl::OkStatus();
}

void Relaxation::Gather(uint32_t i, const Vec3& lo, const Vec3& hi,
                        std::vector<HashGrid::Entry>* near) const {
  near->clear();
  const double ri = r_[i];
  const Vec3 a = {lo.x - ri, lo.y - ri, lo.z - ri}, b = {hi.x + ri, hi.y + ri, hi.z + ri};
  const auto keep = [&](const HashGrid::Entry& e) {
    if (e.id != i && e.p.x >= a.x && e.p.x <= b.x && e.p.y >= a.y && e.p.y <= b.y && e.p.z >= a.z &&
        e.p.z <= b.z) {
      near->push_back(e);
    }
    return false;
  };
  const int64_t x1 = main_.Cell(b.x), y1 = main_.Cell(b.y), z1 = main_.Cell(b.z);
  for (int64_t cx = main_.Cell(a.x); cx <= x1; ++cx) {
    const uint64_t sx = HashGrid::Spread(cx);
    for (int64_t cy = main_.Cell(a.y); cy <= y1; ++cy) {
      const uint64_t sxy = sx | HashGrid::Spread(cy) << 1;
      for (int64_t cz = main_.Cell(a.z); cz <= z1; ++cz) {
        const uint64_t morton = sxy | HashGrid::Spread(cz) << 2;
        main_.AnyInMorton(morton, keep);
        moved_grid_.AnyInMorton(morton, keep);
      }
    }
  }
}

double Relaxation::Crowding(uint32_t i, const Vec3& x, double floor,
                            const std::vector<HashGrid::Entry>& near) const {
  const double ri = r_[i];
  double worst = 1;
  for (const HashGrid::Entry& e : near) {
    const double r = std::min(ri, e.r);
    const Vec3 d = e.p - x;
    const double d2 = Dot(d, d);
    if (d2 < r * r) {
      worst = std::min(worst, d2 / (r * r));
      if (worst <= floor) return worst;
    }
  }
  return worst;
}

absl::Status Relaxation::HalfSweep(int sweep, const std::vector<uint32_t>& todo,
                                   std::vector<uint32_t>* moved) {
  const uint64_t candidates = static_cast<uint64_t>(options_.candidates);
  // Most samples are crowded in the first sweeps, and few candidates help
  // them as much as many; the few left later get all C.
  const uint64_t tries = std::min<uint64_t>(
      candidates, static_cast<uint64_t>(options_.first_candidates) << std::min(sweep, 20));
  // The half-sweep's outcome for todo[t] (kept between half-sweeps: fresh
  // memory costs page faults).
  std::vector<uint8_t>& moves = moves_;
  std::vector<double>& new_q = new_q_;
  std::vector<Vec3>& new_p = new_p_;
  moves.assign(todo.size(), 0);
  new_q.resize(todo.size());
  new_p.resize(todo.size());
  RETURN_IF_ERROR(ForParts(todo.size(), [&](int, size_t begin, size_t end) -> absl::Status {
    // The part's samples that are too close, in index order, with the
    // crowding of their best place so far (their own at first).
    struct Search {
      uint32_t t;
      double best;
      double q;
      Vec3 p;
    };
    std::vector<Search> searching;
    for (size_t t = begin; t < end; ++t) {
      if ((t - begin) % kCheckEvery == 0) RETURN_IF_ERROR(Check());
      const uint32_t k = todo[t];
      // Two samples of the colour that are too close would both move, each
      // away from where the other was, and may meet again: only the one of
      // higher priority moves this sweep.
      double c = 1;
      bool waits = false;
      int neighbours = 0;
      const uint64_t mine = Priority(sweep, k);
      AnyNear(k, p_[k], [&](uint32_t j, double ratio2) {
        c = std::min(c, ratio2);
        waits = waits || (in_todo_[j] && Priority(sweep, j) > mine);
        return ++neighbours >= kMostNeighbours;
      });
      if (neighbours >= kMostNeighbours) {
        frozen_[k] = 1;  // the surface is thinner than the spacing here
      } else if (c >= 1) {
        suspect_[k] = 0;
      } else if (!waits) {
        searching.push_back({static_cast<uint32_t>(t), c, q_[k], p_[k]});
      }
    }
    // A searching sample's `tries` candidates are stratified over its
    // stratum, candidate j at h = (j + U_j) / tries, so their q rise with j
    // (the batch needs no sort) and cover the stratum evenly. They are
    // tried in the order j = (o + t s) mod tries, t = 0, 1, ..., with o and
    // the step s (prime to tries) hashed: neighbouring candidates, which are
    // crowded alike, are not tried one after the other.
    std::vector<double> cq;
    std::vector<Vec3> cp;
    std::vector<double> cd;
    std::vector<HashGrid::Entry> near;
    const size_t block = std::max<size_t>(1, kBlockCandidates / tries);
    for (size_t s0 = 0; s0 < searching.size(); s0 += block) {
      RETURN_IF_ERROR(Check());
      const size_t s1 = std::min(searching.size(), s0 + block);
      cq.clear();
      for (size_t s = s0; s < s1; ++s) {
        const uint64_t k = todo[searching[s].t];
        for (uint64_t j = 0; j < tries; ++j) {
          const uint64_t counter = (k * options_.sweeps + sweep) * candidates + j;
          const double u = UniformOf(CounterHash(seed_, hash_stream::kBlueCandidate, counter));
          const double h = (static_cast<double>(j) + u) / static_cast<double>(tries);
          cq.push_back((static_cast<double>(k) + h) / static_cast<double>(n_));
        }
      }
      cp.resize(cq.size());
      cd.resize(uniform_density_ ? 0 : cq.size());
      RETURN_IF_ERROR(
          place_(cq.data(), cq.size(), cp.data(), uniform_density_ ? nullptr : cd.data()));
      // A sample takes its first candidate, in the hashed order, that
      // clears every neighbour; failing that, the least crowded one.
      for (size_t s = s0; s < s1; ++s) {
        Search& search = searching[s];
        const uint32_t k = todo[search.t];
        const size_t c0 = (s - s0) * tries;
        // The neighbours of all the candidates, gathered once from the
        // grids: they lie in the sample's stratum, so one box holds them.
        Vec3 lo = cp[c0], hi = cp[c0];
        for (uint64_t j = 0; j < tries; ++j) {
          const Vec3& x = cp[c0 + j];
          if (!IsFinite(x)) return absl::InvalidArgumentError("a candidate is not finite");
          lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
          hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
        }
        const bool one_by_one = GatherCells(k, lo, hi) > kMostGatherCells;
        if (!one_by_one) Gather(k, lo, hi, &near);
        const uint64_t order = CounterHash(seed_, hash_stream::kBlueOrder,
                                           static_cast<uint64_t>(k) * options_.sweeps + sweep);
        uint64_t step = (order >> 32) % tries;
        while (std::gcd(step, tries) != 1) ++step;  // (o + t s) mod tries visits every j
        bool cleared = false;
        for (uint64_t t = 0, j = order % tries; t < tries && !cleared;
             ++t, j = (j + step) % tries) {
          const size_t c = c0 + j;
          // Across a density step a stratum's sample would drift to the
          // sparse side, where it is less crowded: it stays where the
          // density is within kDensityJump of its jittered place's.
          if (!uniform_density_ &&
              !(cd[c] * kDensityJump >= delta_[k] && cd[c] <= kDensityJump * delta_[k])) {
            continue;
          }
          const double crowding =
              one_by_one ? CrowdingAt(k, cp[c]) : Crowding(k, cp[c], search.best, near);
          if (crowding >= 1 || crowding > search.best) {
            // Ties go to the first in the hashed order.
            search.best = crowding, search.q = cq[c], search.p = cp[c];
            cleared = crowding >= 1;
          }
        }
      }
    }
    for (const Search& search : searching) {
      if (search.q == q_[todo[search.t]]) continue;  // nothing less crowded than its place
      moves[search.t] = 1, new_q[search.t] = search.q, new_p[search.t] = search.p;
    }
    return absl::OkStatus();
  }));
  // Jacobi: the colour's moves take effect together.
  for (size_t t = 0; t < todo.size(); ++t) {
    if (!moves[t]) continue;
    q_[todo[t]] = new_q[t], p_[todo[t]] = new_p[t];
    moved->push_back(todo[t]);
  }
  return absl::OkStatus();
}

absl::StatusOr<BlueNoiseSet> Relaxation::Run(double total_mass) {
  if (!(options_.rho > 0 && options_.rho <= 0.9) || options_.sweeps < 1 ||
      options_.candidates < 1 || options_.first_candidates < 1) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "blue noise needs 0 < rho <= 0.9, sweeps >= 1 and candidates >= 1 (got %g, %d, %d, %d)",
        options_.rho, options_.sweeps, options_.first_candidates, options_.candidates));
  }
  if (n_ >= std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError("blue noise takes fewer than 2^32 samples");
  }
  // The jittered set and the density at its points.
  q_.resize(n_);
  Sequence(SequenceKind::kJittered, n_, seed_).AtMany(0, n_, q_.data());

  p_.resize(n_);
  std::vector<double>& delta = delta_;
  delta.resize(n_);
  RETURN_IF_ERROR(ForParts(n_, [&](int, size_t begin, size_t end) -> absl::Status {
    for (size_t b = begin; b < end; b += kCheckEvery) {
      RETURN_IF_ERROR(Check());
      const size_t e = std::min(end, b + kCheckEvery);
      RETURN_IF_ERROR(place_(q_.data() + b, e - b, p_.data() + b, delta.data() + b));
    }
    return absl::OkStatus();
  }));
  uniform_density_ =
      std::all_of(delta.begin(), delta.end(), [&](double x) { return x == delta[0]; });
  // Spacing: the hexagonal packing's nearest-neighbour distance for the area
  // a sample has at its density, sqrt(2 a / sqrt 3) with a = S_M / (N delta).
  const double per_sample = total_mass / static_cast<double>(n_);
  std::vector<double> d(n_);
  for (uint64_t i = 0; i < n_; ++i) {
    if (!IsFinite(p_[i]) || !std::isfinite(delta[i]) || delta[i] < 0) {
      return absl::InvalidArgumentError(
          absl::StrFormat("blue noise: sample %d has a point or density that is not finite", i));
    }
    d[i] = delta[i] > 0 ? std::sqrt(2 * per_sample / (std::sqrt(3.0) * delta[i]))
                        : std::numeric_limits<double>::infinity();
  }
  std::vector<double> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + n_ / 2, sorted.end());
  const double median = sorted[n_ / 2];
  if (!(median > 0 && std::isfinite(median))) {
    return absl::InvalidArgumentError("blue noise: the density is zero at most samples");
  }
  r_.resize(n_);
  for (uint64_t i = 0; i < n_; ++i)
    r_[i] = options_.rho * std::min(d[i], kMaxSpacingRatio * median);
  const double cell = kCellRadii * options_.rho * median;

  suspect_.assign(n_, 1);
  in_todo_.assign(n_, 0);
  // The points in `main_` as they were at its build, but for those that
  // moved since (moved_since_build, listed at their current place in
  // moved_grid_).
  std::vector<uint32_t> all(n_), slot(n_), moved_since_build, colour, moved;
  std::vector<uint8_t> moved_flag(n_, 0), ever_moved(n_, 0);
  for (uint32_t i = 0; i < n_; ++i) all[i] = i;
  main_ = HashGrid(cell);
  moved_grid_ = HashGrid(cell);
  main_.Build(p_, r_, all, &slot);
  RETURN_IF_ERROR(FreezeBesideJumps());
  for (int sweep = 0; sweep < options_.sweeps; ++sweep) {
    if (moved_since_build.size() > n_ / 8) {
      main_.Build(p_, r_, all, &slot);
      for (uint32_t i : moved_since_build) moved_flag[i] = 0;
      moved_since_build.clear();
      moved_grid_.Clear();
    }
    for (uint32_t c = 0; c < 2; ++c) {
      colour.clear();
      for (uint32_t i = c; i < n_; i += 2) {
        if (suspect_[i] && !frozen_[i]) colour.push_back(i);
      }
      if (colour.empty()) continue;
      RETURN_IF_ERROR(Check());
      moved.clear();
      for (uint32_t i : colour) in_todo_[i] = 1;
      RETURN_IF_ERROR(HalfSweep(sweep, colour, &moved));
      for (uint32_t i : colour) in_todo_[i] = 0;
      if (moved.empty()) continue;
      for (uint32_t i : moved) {
        ever_moved[i] = 1;
        if (moved_flag[i]) continue;
        moved_flag[i] = 1;
        main_.Kill(slot[i]);
        moved_since_build.push_back(i);
      }
      moved_grid_.Build(p_, r_, moved_since_build, nullptr);
      // A sample that moved to a place clearing every neighbour can be too
      // close only to another that moved with it; one that moved to its
      // least crowded candidate is too close to some: both are suspects.
      std::vector<std::vector<uint32_t>> close(threads_);
      RETURN_IF_ERROR(ForParts(moved.size(), [&](int part, size_t begin, size_t end) {
        std::vector<uint32_t>& mine = close[part];
        for (size_t t = begin; t < end; ++t) {
          const uint32_t k = moved[t];
          suspect_[k] = 0;
          int neighbours = 0;
          AnyNear(k, p_[k], [&](uint32_t j, double) {
            mine.push_back(k), mine.push_back(j);
            return ++neighbours >= kMostNeighbours;
          });
        }
        return absl::OkStatus();
      }));
      for (const std::vector<uint32_t>& part : close) {
        for (uint32_t k : part) suspect_[k] = 1;
      }
    }
  }
  BlueNoiseSet out;
  for (uint64_t i = 0; i < n_; ++i) {
    out.moved += ever_moved[i];
    // Suspects are re-checked: one may have been cleared by a neighbour's move.
    if (suspect_[i] && Conflicts(static_cast<uint32_t>(i), p_[i])) ++out.unresolved;
  }
  out.q = std::make_shared<const std::vector<double>>(std::move(q_));
  return out;
}

}  // namespace

absl::StatusOr<BlueNoiseSet> RelaxBlueNoise(uint64_t count, uint64_t seed, double total_mass,
                                            const MassPlacer& place, int threads,
                                            const BlueNoiseOptions& options) {
  if (count == 0) return absl::InvalidArgumentError("blue noise needs count >= 1");
  Relaxation relaxation(count, seed, place, threads, options);
  return relaxation.Run(total_mass);
}

}  // namespace sfc
