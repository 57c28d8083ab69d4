// What a client asks for, independent of transport: the embedded CLI and the
// gRPC server both fill a SampleRequest and hand it to a SamplingEngine, so
// the two produce identical samples by construction. Part of the request
// library (request/), which the client links without the sampler.
// Value types; thread-compatible.
#ifndef SFCSAMPLER_REQUEST_SAMPLE_REQUEST_H_
#define SFCSAMPLER_REQUEST_SAMPLE_REQUEST_H_

#include <cstdint>
#include <string>

#include "core/types/region.h"
#include "core/types/sample_batch.h"
#include "core/types/sequence_kind.h"
#include "core/types/tree_options.h"

namespace sfc {

// Bumped whenever the same request could yield different samples.
// 2: error-controlled tree, in-leaf model descent; 3: per-cell power laws
// toward singular edges (LeafModel::warp), placement inside a leaf by tables
// (core/leaf_walk.h), elementary functions from SLEEF (core/vector_math.h).
// Its bytes are pinned by tests/pinned_bytes.txt.
inline constexpr char kAlgorithmVersion[] = "sfcsampler-4";

// Everything that shapes a curve tree (the cache key) except its grade.
struct TreeSpec {
  std::string surface = "sphere";   // catalogue spec, see catalog/catalog.h
  std::string density = "uniform";  // catalogue spec
  CurveTreeOptions options;         // curve, estimator, tolerance, depth cap, rho
};

struct SampleRequest {
  TreeSpec tree;
  SequenceKind sequence = SequenceKind::kJittered;
  uint64_t count = 0;       // N, the size of the whole set; >= 1
  uint64_t seed = 0;
  uint64_t tree_count = 0;  // size the tree for this many samples; 0 = count.
                            // Progressive extensions pass the same value each time.
  // Which part of the set: indices [begin, end) (end 0 = count), or shard
  // `shard_index` of `shard_count` (shard_count 0 = none), then `region`.
  uint64_t begin = 0, end = 0;
  uint64_t shard_index = 0, shard_count = 0;
  Region region;
  SampleFields fields;
};
}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_SAMPLE_REQUEST_H_
