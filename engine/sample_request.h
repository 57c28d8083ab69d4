// What a client asks for, independent of transport: the embedded CLI and the
// gRPC server both fill a SampleRequest and hand it to a SamplingEngine, so
// the two produce identical samples by construction.
// Value types; thread-compatible.
#ifndef SFCSAMPLER_ENGINE_SAMPLE_REQUEST_H_
#define SFCSAMPLER_ENGINE_SAMPLE_REQUEST_H_

#include <cstdint>
#include <string>

#include "core/curve_tree.h"
#include "core/region.h"
#include "core/sample_batch.h"
#include "core/sequence.h"

namespace sfc {

// Bumped whenever the same request could yield different samples.
// 2: error-controlled tree, in-leaf model descent; 3: per-cell power laws
// toward singular edges (LeafModel::warp), placement inside a leaf by tables
// (core/leaf_walk.h), elementary functions from SLEEF (core/vector_math.h).
// Its bytes are pinned by tests/pinned_bytes.txt.
inline constexpr char kAlgorithmVersion[] = "sfcsampler-3";

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

// Limits that every request is checked against (server flags).
struct EngineLimits {
  uint64_t max_count = 100'000'000;              // largest N
  uint64_t max_tree_leaves = uint64_t{1} << 22;  // per tree: 73 B a leaf (CurveTree::kBytesPerLeaf), 292 MiB
  size_t max_spec_length = 4096;                 // surface/density spec, in characters
  int generation_threads = 1;                    // threads filling one stream's large batches
  // Sequences that are not monotone in k are sorted into curve order per
  // request (16 bytes a sample): at most this many samples per request.
  uint64_t max_sorted_range = uint64_t{1} << 24;
  // Model files (CAD, meshes) are parsed on threads of their own
  // (engine/loaded_models.h): parsed models kept, bytes (LRU past it);
  // parses at once; parses that may wait for a thread; CPU seconds one parse
  // may take (0 = no limit: the CLI's own files); how long a failed parse is
  // remembered.
  uint64_t parsed_model_bytes = uint64_t{256} << 20;
  int model_parse_threads = 1;
  int max_queued_parses = 8;
  double model_parse_seconds = 0;
  double parse_failure_ttl_seconds = 60;
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_SAMPLE_REQUEST_H_
