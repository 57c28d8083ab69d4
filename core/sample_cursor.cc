#include "core/sample_cursor.h"

#include <algorithm>
#include <cassert>
#include <utility>

#include "absl/strings/str_format.h"
#include "base/column_memory.h"
#include "base/status_macros.h"
#include "base/worker_pool.h"

namespace sfc {
namespace {

// The columns a cursor fills: the triangle only where the kind has one; the
// face is CAD's, added above the cursor (cad/model_sampler.h).
SampleFields ColumnsOf(const CurveSamples& samples, SampleFields fields) {
  fields.triangle = fields.triangle && samples.has_triangles();
  fields.face = false;
  return fields;
}

// Permutes at[0, n) in place so that the addresses of each bucket come
// together, buckets in increasing order (McIlroy, Bostic and McIlroy's
// American flag sort, 1993): bucket(a) in [0, buckets). `end` (buckets
// entries) returns where each bucket ends; when `counted`, it comes in
// holding each bucket's count.
template <typename Bucket>
void PermuteIntoBuckets(CurveAddress* at, size_t n, uint64_t buckets, const Bucket& bucket,
                        std::vector<uint32_t>* end, bool counted = false) {
  constexpr size_t kAhead = 8;  // addresses: two cache lines
  if (!counted) {
    end->assign(buckets, 0);
    for (size_t j = 0; j < n; ++j) ++(*end)[bucket(at[j])];
  }
  std::vector<uint32_t> next(buckets);  // each bucket's first place not yet filled
  uint32_t running = 0;
  for (uint64_t c = 0; c < buckets; ++c) {
    next[c] = running, running += (*end)[c], (*end)[c] = running;
  }
  for (uint64_t c = 0; c < buckets; ++c) {
    while (next[c] < (*end)[c]) {
      // Carry the address at c's next place along its cycle until one of
      // c's own comes back to it.
      CurveAddress carried = at[next[c]];
      for (uint64_t b = bucket(carried); b != c; b = bucket(carried)) {
        // Each swap's place depends on the address carried there: a chain of
        // loads, each bucket's next place fetched ahead so that it hits cache.
        __builtin_prefetch(at + next[b] + kAhead, 1);
        std::swap(carried, at[next[b]++]);
      }
      at[next[c]++] = carried;
    }
  }
}

// Copies at[0, n) to out[0, n) with the addresses of each bucket together,
// buckets in increasing order, each in its order in `at`: bucket(a) in [0,
// buckets). `end` (buckets entries) returns where each bucket ends. Unlike
// PermuteIntoBuckets, no store waits on a load: for addresses in cache.
template <typename Bucket>
void DistributeIntoBuckets(const CurveAddress* at, size_t n, uint64_t buckets, const Bucket& bucket,
                           CurveAddress* out, std::vector<uint32_t>* end) {
  end->assign(buckets, 0);
  for (size_t j = 0; j < n; ++j) ++(*end)[bucket(at[j])];
  uint32_t running = 0;
  for (uint64_t c = 0; c < buckets; ++c) {
    const uint32_t count = (*end)[c];
    (*end)[c] = running;  // its first place, until the copy below moves it on
    running += count;
  }
  for (size_t j = 0; j < n; ++j) out[(*end)[bucket(at[j])]++] = at[j];
}

// Sorts a bucket's few addresses, all of one leaf, into curve order: by
// insertion, on digits then index (CurveAddress::Key's order within a leaf).
void SortWithinLeaf(CurveAddress* first, CurveAddress* last) {
  for (CurveAddress* i = first + 1; i < last; ++i) {
    const CurveAddress moved = *i;
    CurveAddress* j = i;
    for (; j > first; --j) {
      const CurveAddress& before = j[-1];
      if (before.digits < moved.digits ||
          (before.digits == moved.digits && before.index < moved.index)) {
        break;
      }
      *j = before;
    }
    *j = moved;
  }
}

// The buckets by which SortAddresses sorts n addresses whose leaves are
// below `leaves`: the leaf and the digits' top `bits` (as many as make about
// two addresses a bucket), in two passes, first by the top 8 bits of the
// bucket (the coarse bucket, below 256), then each coarse bucket by the rest
// (the fine bucket, below 2^fine_bits). `compare`: more leaves than half the
// addresses (a large mesh, a small set), or too many addresses for 32-bit
// counts, take one comparison sort instead, O(N log N).
struct AddressBuckets {
  AddressBuckets(uint32_t leaves, size_t n) {
    compare = n < 2 || leaves > n / 2 + 1024 || n >= (uint64_t{1} << 32);
    if (compare) return;
    while (bits < 20 && (uint64_t{leaves} << (bits + 1)) <= n / 2) ++bits;
    const uint64_t buckets = uint64_t{leaves} << bits;
    while ((buckets - 1) >> fine_bits >= 256) ++fine_bits;
    coarse = ((buckets - 1) >> fine_bits) + 1;
  }
  // Digits are below 2^52 (CurveAddress::Key); bits above are ignored.
  uint64_t Of(const CurveAddress& a) const {
    return (uint64_t{a.leaf} << bits) | ((a.digits & kDigits) >> (52 - bits));
  }
  uint64_t CoarseOf(const CurveAddress& a) const { return Of(a) >> fine_bits; }
  // Writes a's coarse bucket into its digits' unused top 8 bits (the first
  // pass's bucket, no shifts by variable counts in its chain of loads) and
  // returns it; SortAddresses clears them.
  // REQUIRES: a.leaf < the bound the buckets were sized for
  // (CurveSamples::AddressLeafBound), so c < coarse <= 256 fits the 8 bits.
  uint64_t Stamp(CurveAddress* a) const {
    const uint64_t c = CoarseOf(*a);
    assert(c < coarse && coarse <= 256);
    a->digits |= c << kStampShift;
    return c;
  }

  static constexpr uint64_t kDigits = (uint64_t{1} << 52) - 1;
  static constexpr int kStampShift = 56;
  bool compare = false;
  int bits = 0, fine_bits = 0;
  uint64_t coarse = 0;
};

// Sorts addresses into curve order (by CurveAddress::Key), in place, by
// `buckets`, each stamped with its coarse bucket (AddressBuckets::Stamp)
// unless buckets.compare; coarse_count[c] holds how many lie in coarse
// bucket c. The first pass permutes them in place into their coarse buckets
// (so it writes to at most 256 places at a time, each fetched ahead); the
// second, split over `parts` threads, takes each coarse bucket while it is in
// cache into its fine buckets, and each fine bucket's few addresses by key.
// The order is that of one sort of the whole (keys are distinct: they hold
// the index). Beside the addresses it holds two tables of 2^fine_bits counts
// a thread (4 bytes each: about 256 KB a thread at 2^24 samples) and a copy
// of one coarse bucket (at most 1 MB a thread).
void SortAddresses(std::vector<CurveAddress>* addresses, const AddressBuckets& buckets,
                   std::vector<uint32_t> coarse_count, int parts) {
  // The second pass's copy of a coarse bucket, at most 1 MB a thread.
  constexpr size_t kScratchAddresses = size_t{1} << 16;
  std::vector<CurveAddress>& at = *addresses;
  if (buckets.compare) {
    std::sort(at.begin(), at.end());
    return;
  }
  const int fine_bits = buckets.fine_bits;
  const uint64_t coarse = buckets.coarse;
  std::vector<uint32_t> coarse_end = std::move(coarse_count);
  PermuteIntoBuckets(
      at.data(), at.size(), coarse,
      [](const CurveAddress& a) { return a.digits >> AddressBuckets::kStampShift; }, &coarse_end,
      /*counted=*/true);
  // Coarse buckets to parts of about equal counts.
  WorkerPool::Shared().ParallelFor(parts, [&](int i) {
    const uint64_t from = at.size() * i / parts, to = at.size() * (i + 1) / parts;
    std::vector<uint32_t> end;
    std::vector<CurveAddress> scratch;
    for (uint64_t c = 0; c < coarse; ++c) {
      const uint64_t begin = c == 0 ? 0 : coarse_end[c - 1];
      // Each coarse bucket with addresses is the part's where it begins.
      if (begin < from || begin >= to || coarse_end[c] == begin) continue;
      CurveAddress* first = at.data() + begin;
      const size_t n = coarse_end[c] - begin;
      for (size_t j = 0; j < n; ++j) first[j].digits &= AddressBuckets::kDigits;
      const uint64_t base = c << fine_bits;
      auto fine_bucket = [&](const CurveAddress& a) { return buckets.Of(a) - base; };
      // A coarse bucket of cache size is copied into buckets and back (no
      // chain of loads); a larger one (a leaf with most of the mass) is
      // permuted in place.
      CurveAddress* sorted = first;
      if (n <= kScratchAddresses) {
        scratch.resize(std::max(scratch.size(), n));
        DistributeIntoBuckets(first, n, uint64_t{1} << fine_bits, fine_bucket, scratch.data(),
                              &end);
        sorted = scratch.data();
      } else {
        PermuteIntoBuckets(first, n, uint64_t{1} << fine_bits, fine_bucket, &end);
      }
      for (size_t f = 0; f < end.size(); ++f) {
        const uint32_t b = f == 0 ? 0 : end[f - 1];
        if (end[f] - b > 1) SortWithinLeaf(sorted + b, sorted + end[f]);
      }
      if (sorted != first) std::copy(sorted, sorted + n, first);
    }
  });
}

}  // namespace

SampleCursor::SampleCursor(std::shared_ptr<const CurveSamples> samples, Region region,
                           SampleFields fields)
    : samples_(std::move(samples)),
      region_(region),
      fields_(ColumnsOf(*samples_, fields)),
      filler_(samples_->NewFiller(region_, fields_)) {}

absl::StatusOr<std::unique_ptr<SampleCursor>> SampleCursor::Create(
    std::shared_ptr<const CurveSamples> samples, uint64_t begin, uint64_t end,
    const Region& region, const SampleFields& fields, int threads,
    const std::vector<uint32_t>* in_window) {
  const uint64_t count = samples->sequence().count();
  if (begin > end || end > count) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the index range [%d, %d) is not inside the set of %d samples; it needs begin <= end <= "
        "count",
        begin, end, count));
  }
  RETURN_IF_ERROR(samples->AcceptsSequence(samples->sequence()));
  RETURN_IF_ERROR(samples->AcceptsRegion(region));
  RETURN_IF_ERROR(region.Validate());
  auto cursor = std::unique_ptr<SampleCursor>(new SampleCursor(std::move(samples), region, fields));
  cursor->threads_ = std::max(1, threads);
  RETURN_IF_ERROR(cursor->Plan(begin, end, in_window));
  return cursor;
}

absl::Status SampleCursor::Plan(uint64_t begin, uint64_t end,
                                const std::vector<uint32_t>* in_window) {
  const CurveSamples& samples = *samples_;
  if (samples.sequence().two_dimensional()) {
    // Points warped onto the surface: the whole set in curve order, of which
    // [begin, end) are positions, so ranges and shards concatenate to it.
    // Addresses are pure functions of k, computed in parts over the threads.
    const Sequence& sequence = samples.sequence();
    const uint64_t count = sequence.count();
    // A window's samples (a CAD face's) are found first, so only they are
    // warped and sorted: one face's cursor costs its own share of the set,
    // not the whole set's warp and sort.
    std::vector<uint32_t> found;
    if (sequence.windowed() && in_window == nullptr) {
      for (uint64_t k = 0; k < count; ++k) {
        if (sequence.InWindow(k)) found.push_back(static_cast<uint32_t>(k));
      }
      in_window = &found;
    }
    const uint32_t* ks = sequence.windowed() ? in_window->data() : nullptr;
    const uint64_t m = sequence.windowed() ? in_window->size() : count;
    ResizeColumn(&addresses_, m);
    const int parts = m >= 8192 ? threads_ : 1;
    // Each part stamps and counts its addresses' coarse buckets while they
    // are in cache.
    const AddressBuckets buckets(samples.AddressLeafBound(), m);
    std::vector<std::vector<uint32_t>> counts(parts);
    WorkerPool::Shared().ParallelFor(parts, [&](int i) {
      const uint64_t j0 = m * i / parts, j1 = m * (i + 1) / parts;
      constexpr uint64_t kPiece = 4096;
      if (!buckets.compare) counts[i].assign(buckets.coarse, 0);
      for (uint64_t p = j0; p < j1; p += kPiece) {
        const uint64_t n = std::min(kPiece, j1 - p);
        samples.AddressesOf(ks != nullptr ? ks + p : nullptr, p, n, addresses_.data() + p);
        if (buckets.compare) continue;
        for (uint64_t j = p; j < p + n; ++j) ++counts[i][buckets.Stamp(&addresses_[j])];
      }
    });
    std::vector<uint32_t> coarse_count(buckets.coarse, 0);
    for (const std::vector<uint32_t>& part : counts) {
      for (uint64_t c = 0; c < part.size(); ++c) coarse_count[c] += part[c];
    }
    SortAddresses(&addresses_, buckets, std::move(coarse_count), parts);
    const uint64_t kept = addresses_.size();
    addresses_.erase(addresses_.begin() + std::min(end, kept), addresses_.end());
    addresses_.erase(addresses_.begin(), addresses_.begin() + std::min(begin, kept));
    addresses_.shrink_to_fit();
    use_addresses_ = true;
    return absl::OkStatus();
  }
  if (!samples.sequence().monotone()) {
    // Index order is not curve order.
    const Sequence& sequence = samples.sequence();
    order_ = IndicesInCurveOrder(
        begin, end, [&](uint64_t k) { return samples.MassCoordinate(k); },
        [&](uint64_t k) { return sequence.InWindow(k); });
    use_order_ = true;
    return absl::OkStatus();
  }
  if (region_.kind == Region::Kind::kAll) {
    if (begin < end) segments_.push_back({begin, end});
  } else {
    RETURN_IF_ERROR(samples.PlanRegion(region_, begin, end, &segments_));
  }
  if (!segments_.empty()) next_k_ = segments_[0].begin;
  return absl::OkStatus();
}

absl::StatusOr<size_t> SampleCursor::Next(size_t max, SampleBatch* batch) {
  const size_t s0 = batch->size();
  absl::StatusOr<size_t> produced = NextRuns(max, batch);
  if (!produced.ok()) Truncate(batch, s0);
  return produced;
}

absl::StatusOr<size_t> SampleCursor::NextRuns(size_t max, SampleBatch* batch) {
  // Large runs inside one plain index range are split over threads.
  constexpr size_t kMinParallel = 8192;
  size_t produced = 0;
  while (produced < max) {
    // The next run: at most the samples still wanted, inside one segment. A
    // region keeps fewer than it is handed, so runs repeat until max are kept.
    size_t kept;
    if (use_addresses_) {
      if (order_pos_ >= addresses_.size()) break;
      const size_t n = std::min<size_t>(max - produced, addresses_.size() - order_pos_);
      const CurveAddress* at = addresses_.data() + order_pos_;
      if (threads_ > 1 && region_.kind == Region::Kind::kAll && n >= kMinParallel) {
        RETURN_IF_ERROR(GenerateParallel(0, n, batch, at));
        kept = n;
      } else {
        ASSIGN_OR_RETURN(kept, Generate(0, nullptr, n, batch, at));
      }
      order_pos_ += n;
    } else if (use_order_) {
      if (order_pos_ >= order_.size()) break;
      const size_t n = std::min<size_t>(max - produced, order_.size() - order_pos_);
      ASSIGN_OR_RETURN(kept, Generate(0, order_.data() + order_pos_, n, batch));
      order_pos_ += n;
    } else {
      if (segment_ >= segments_.size()) break;
      const size_t n = std::min<uint64_t>(max - produced, segments_[segment_].end - next_k_);
      if (threads_ > 1 && region_.kind == Region::Kind::kAll && n >= kMinParallel) {
        RETURN_IF_ERROR(GenerateParallel(next_k_, n, batch));
        kept = n;
      } else {
        ASSIGN_OR_RETURN(kept, Generate(next_k_, nullptr, n, batch));
      }
      next_k_ += n;
      if (next_k_ >= segments_[segment_].end && ++segment_ < segments_.size()) {
        next_k_ = segments_[segment_].begin;
      }
    }
    produced += kept;
  }
  return produced;
}

SampleRows SampleCursor::Grow(SampleBatch* batch, size_t n) const {
  const size_t s0 = batch->size(), rows = s0 + n;
  batch->ForEachColumn(fields_, [&](auto* column) { ResizeColumn(column, rows); });
  // The columns `fields_` hold grew to `rows` (n >= 1); the others stayed at
  // s0 (a batch keeps one set of columns) and get no rows.
  auto rows_of = [&](auto& column) -> decltype(column.data()) {
    return n > 0 && column.size() == rows ? column.data() + s0 : nullptr;
  };
  SampleRows out;
  out.index = rows_of(batch->index);
  out.u = rows_of(batch->u), out.v = rows_of(batch->v);
  out.x = rows_of(batch->x), out.y = rows_of(batch->y), out.z = rows_of(batch->z);
  out.nx = rows_of(batch->nx), out.ny = rows_of(batch->ny), out.nz = rows_of(batch->nz);
  out.density = rows_of(batch->density);
  out.curve_position = rows_of(batch->curve_position);
  out.triangle = rows_of(batch->triangle);
  return out;
}

void SampleCursor::Truncate(SampleBatch* batch, size_t rows) const {
  batch->ForEachColumn(fields_, [&](auto* column) { column->resize(rows); });
}

absl::Status SampleCursor::Fill(uint64_t k0, const uint64_t* order, size_t n,
                                SampleFiller& filler, const SampleRows& out,
                                const CurveAddress* at) const {
  // Runs of at most kFillRun samples, so that the filler's passes over a
  // run's columns stay in cache: one call for 4 M samples had streamed each
  // pass's 32 MB columns through memory.
  for (size_t done = 0; done < n; done += kFillRun) {
    const size_t run = std::min(kFillRun, n - done);
    RETURN_IF_ERROR(FillRun(k0 + done, order != nullptr ? order + done : nullptr, run, filler,
                            out.From(done), at != nullptr ? at + done : nullptr));
  }
  return absl::OkStatus();
}

absl::Status SampleCursor::FillRun(uint64_t k0, const uint64_t* order, size_t n,
                                   SampleFiller& filler, const SampleRows& out,
                                   const CurveAddress* at) const {
  const CurveSamples& samples = *samples_;
  if (at != nullptr) {
    for (size_t i = 0; i < n; ++i) out.index[i] = at[i].index;
    return filler.FillAddressed(n, at, out);
  }
  // Mass coordinates q_k S_M, in x until the filler overwrites them.
  double* m = out.x;
  if (order == nullptr) {
    samples.sequence().AtMany(k0, n, m);
    const double total_mass = samples.total_mass();
    for (size_t i = 0; i < n; ++i) {
      m[i] *= total_mass;
      out.index[i] = k0 + i;
    }
  } else {
    for (size_t i = 0; i < n; ++i) {
      m[i] = samples.MassCoordinate(order[i]);
      out.index[i] = order[i];
    }
  }
  return filler.Fill(n, out);
}

absl::StatusOr<size_t> SampleCursor::Generate(uint64_t k0, const uint64_t* order, size_t n,
                                              SampleBatch* batch, const CurveAddress* at) {
  const size_t s0 = batch->size();
  const SampleRows out = Grow(batch, n);
  if (absl::Status st = Fill(k0, order, n, *filler_, out, at); !st.ok()) {
    Truncate(batch, s0);
    return st;
  }
  if (region_.kind == Region::Kind::kAll) return n;
  // Keep the rows inside the region, in order.
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!region_.Contains(out.u[i], out.v[i], {out.x[i], out.y[i], out.z[i]})) continue;
    if (kept != i) {
      out.index[kept] = out.index[i];
      for (double* column : {out.u, out.v, out.x, out.y, out.z, out.nx, out.ny, out.nz,
                             out.density, out.curve_position}) {
        if (column != nullptr) column[kept] = column[i];
      }
      if (out.triangle != nullptr) out.triangle[kept] = out.triangle[i];
    }
    ++kept;
  }
  Truncate(batch, s0 + kept);
  return kept;
}

absl::Status SampleCursor::GenerateParallel(uint64_t k0, size_t n, SampleBatch* batch,
                                            const CurveAddress* at) {
  // threads_ contiguous parts of the run, on the shared pool, each filling its
  // own rows of the grown columns; part 0 with the cursor's filler, the others
  // with theirs. A sample is a pure function of k, so the bytes are the same
  // for any split.
  const size_t s0 = batch->size();
  const SampleRows out = Grow(batch, n);
  const int parts = threads_;
  while (part_fillers_.size() + 1 < static_cast<size_t>(parts)) {
    part_fillers_.push_back(samples_->NewFiller(region_, fields_));
  }
  std::vector<absl::Status> status(parts);
  auto bound = [&](int i) { return n * i / parts; };
  WorkerPool::Shared().ParallelFor(parts, [&](int i) {
    const size_t begin = bound(i), count = bound(i + 1) - begin;
    const CurveAddress* part_at = at != nullptr ? at + begin : nullptr;
    if (i == 0) {
      status[i] = Fill(k0, nullptr, count, *filler_, out, part_at);
    } else {
      status[i] =
          Fill(k0 + begin, nullptr, count, *part_fillers_[i - 1], out.From(begin), part_at);
    }
  });
  for (const absl::Status& st : status) {
    if (!st.ok()) {
      Truncate(batch, s0);
      return st;
    }
  }
  return absl::OkStatus();
}

}  // namespace sfc
