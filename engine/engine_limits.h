// The limits every request is checked against (the server's flags; the CLI
// and Python take the defaults). Value type.
#ifndef SFCSAMPLER_ENGINE_ENGINE_LIMITS_H_
#define SFCSAMPLER_ENGINE_ENGINE_LIMITS_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace sfc {

struct EngineLimits {
  // Samples one request delivers at most (its index range, shard or whole
  // set), and the largest N of a set. A range of a set of 10^9 generates only
  // its own samples, so only the range is held to max_count; but the tree is
  // sized for N (a torus with a Gaussian density: 0.27 s at 10^9, 6.2 s and
  // 3.3 M leaves at 2^40), so N has a limit of its own.
  uint64_t max_count = 100'000'000;
  uint64_t max_set_count = 1'000'000'000;
  uint64_t max_tree_leaves = uint64_t{1}
                             << 22;  // per tree: 73 B a leaf (CurveTree::kBytesPerLeaf), 292 MiB
  size_t max_spec_length = 4096;     // surface/density spec, in characters
  // Threads filling one stream's large batches, and ordering a mesh's triangles.
  int generation_threads = 1;
  // Sequences that are not monotone in k are sorted into curve order per
  // request (16 bytes a sample): at most this many samples per request.
  uint64_t max_sorted_range = uint64_t{1} << 24;
  // The blue sequence relaxes the whole set in memory (up to
  // kBlueNoiseBytesPerSample a sample, core/blue_relaxation.h) for every
  // request: at most this many samples.
  uint64_t max_blue_count = uint64_t{1} << 24;
  // Model files (CAD, meshes) are parsed on threads of their own
  // (engine/loaded_models.h): parsed models kept, bytes (LRU past it);
  // parses at once; parses that may wait for a thread; CPU seconds one parse
  // may take (0 = no limit: the CLI's own files); how long a failed parse is
  // remembered; working memory of the parses running at once, estimated
  // from each file's size before it starts (0 = no limit).
  uint64_t parsed_model_bytes = uint64_t{256} << 20;
  uint64_t parse_memory_bytes = 0;
  // A program that reads each CAD file in a process of its own
  // (kinds/cad/model_check.h), with model_parse_seconds of CPU, and sends
  // back its shape; "" = read in this process (the CLI's own files).
  std::string model_check_program;
  int model_parse_threads = 1;  // 0: on the requests' own threads (embedded only)
  int max_queued_parses = 8;
  double model_parse_seconds = 0;
  double parse_failure_ttl_seconds = 60;
  // Isolation of parses from each other (engine/loaded_models.h): a parse
  // holds its thread's slot for model_parse_fresh_seconds, then leaves it
  // and yields the CPU (0: it keeps its slot); at most max_long_parses such
  // parses at once; a request waits at most max_parse_queue_seconds for its
  // parse to start (0: no limit).
  double model_parse_fresh_seconds = 0;
  int max_long_parses = 4;
  double max_parse_queue_seconds = 0;
  // A CAD file's CPU budget in the check process grows with its size:
  // min(model_parse_seconds, kParseBaseSeconds + this x its MiB); 0: always
  // model_parse_seconds.
  double model_parse_seconds_per_mib = 0;
  static constexpr double kParseBaseSeconds = 2;
  // The CPU budget of parsing a file of `bytes` (0 = no limit).
  double ParseSecondsFor(uint64_t bytes) const {
    if (model_parse_seconds_per_mib <= 0) return model_parse_seconds;
    const double scaled = kParseBaseSeconds + model_parse_seconds_per_mib * bytes / (1 << 20);
    return model_parse_seconds > 0 && model_parse_seconds < scaled ? model_parse_seconds : scaled;
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_ENGINE_LIMITS_H_
