// Parsed models (meshes, CAD models): parsing a model is a build. Parses run
// on this object's own threads, never on an RPC thread, so a request that
// waits for one holds no stream slot and no lock; the request waits with its
// own check (client gone, deadline) and leaves when it says so. (An embedded
// engine may instead parse on its callers' threads: parse_threads = 0.)
//
//  - Bounded: at most parse_threads parses at once, at most max_queued_parses
//    waiting for a thread (past that a miss is RESOURCE_EXHAUSTED), each with
//    a CPU budget (thread CPU time, parse_seconds) that its ParseControl
//    check reports when spent; a parse nobody waits for any more is told to
//    stop too. The parsers poll the check (CAD: OpenCASCADE's user break).
//  - Short parses first (issue 37: one hostile file held CAD for every
//    client): a parse holds one of the parse_threads slots only for its first
//    fresh_seconds; a parse still running then is "long" and leaves its slot
//    to the parses waiting, runs on at the lowest priority (the CAD check
//    process yields its CPU after that long, kinds/cad/model_check.h), and at
//    most max_long_parses run so at once: past that the largest of them (by
//    working memory, the new one when it is no smaller) is stopped with
//    RESOURCE_EXHAUSTED (the server is busy, not the model at fault: not
//    remembered), so a small model slowed by a busy machine is never the
//    one stopped for hostile large ones. So a small model waits at most
//    fresh_seconds for a slot and then gets the CPU before every long
//    parse, whatever the other clients send or how long they stay.
//  - Smallest first: of the parses waiting, the one with the least working
//    memory (which grows with the file's size) starts next, so a small
//    model does not wait behind large or hostile ones; a parse passed over
//    kMaxPassedOver times starts next whatever its size. A full queue takes
//    a smaller parse in place of its largest (which is told so), and a
//    request leaves a queue it waited in for max_queue_wait_seconds.
//  - One parse per key: requests for a key being parsed wait for that parse.
//  - A failed parse is remembered per key (a model's format + content hash
//    + whatever changes the parse) for failure_ttl_seconds: the same hostile
//    file is not parsed again on every request.
//  - A parse's working memory, estimated by the caller from the file's size
//    (Get's working_bytes), counts against working_budget_bytes while it
//    runs: a parse starts only when its estimate fits beside those running
//    (or none runs), and one whose estimate alone is past the budget is
//    refused before it is queued.
//  - Kept parses are counted in bytes (Parsed::bytes) against budget_bytes,
//    least recently used first out; a parse larger than the budget alone is
//    returned to its requests but not kept. ForgetModel() drops a model's parses
//    (an evicted upload). A model in use stays alive through its shared_ptr.
//
// Thread-safety: thread-safe.
#ifndef SFCSAMPLER_ENGINE_LOADED_MODELS_H_
#define SFCSAMPLER_ENGINE_LOADED_MODELS_H_

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "base/lru.h"

namespace sfc {

struct LoadedModelsOptions {
  uint64_t budget_bytes = uint64_t{256} << 20;  // parsed models kept; default 256 MiB
  // Parses at once, each on a thread of this object's own, >= 1; or 0 (or
  // less): each parse runs on the thread that asked for it (an embedded
  // engine, whose callers are its own threads: no hand-over, no queue). The
  // CPU budget, the one-parse-per-key rule and the caller's check hold as
  // before; working_budget_bytes then bounds each parse alone, not their sum.
  int parse_threads = 1;
  int max_queued_parses = 8;                    // parses waiting for a thread, >= 0
  // How long (wall-clock) a parse holds its slot; past it the parse is long
  // (see above). 0: a parse holds its slot to the end.
  double fresh_seconds = 0;
  int max_long_parses = 4;  // long parses running at once, >= 0
  // Longest a request waits for its parse to start; 0 = no limit.
  double max_queue_wait_seconds = 0;
  // CPU seconds one parse may take (its thread's CPU time); 0 = no budget.
  double parse_seconds = 0;
  double failure_ttl_seconds = 60;  // how long a failed parse is remembered, >= 0
  // Working memory of the parses running at once, bytes; 0 = no limit.
  uint64_t working_budget_bytes = 0;
};

struct LoadedModelsStats {
  uint64_t models = 0;           // kept now
  uint64_t bytes = 0;            // of kept models, now
  uint64_t hits = 0;
  uint64_t parses = 0;           // finished, ok or not
  uint64_t parse_failures = 0;   // remembered failures made
  uint64_t failure_hits = 0;     // requests answered from a remembered failure
  uint64_t parses_stopped = 0;   // abandoned by every request, or out of CPU budget
  uint64_t parses_rejected = 0;  // misses turned away: queue full
  uint64_t evictions = 0;
  uint64_t parsing = 0;          // running now
  uint64_t long_parses = 0;      // running now past fresh_seconds (of parsing)
  uint64_t parses_busy = 0;      // stopped or turned away because the server was busy
  uint64_t queued = 0;           // waiting for a thread now
  uint64_t working_bytes = 0;    // working memory reserved by running parses, now
};

// The status of a parse stopped at its CPU budget of `seconds`
// (RESOURCE_EXHAUSTED): what it spent, which flags set the budget, what to do.
absl::Status ParseBudgetSpent(double seconds);

// What a parse may ask while it runs: OK to go on, or why to stop
// (CANCELLED: nobody waits; RESOURCE_EXHAUSTED: CPU budget spent;
// UNAVAILABLE: shutdown). Cheap enough to call often.
using ParseCheck = std::function<absl::Status()>;

class LoadedModels {
 public:
  struct Parsed {
    std::shared_ptr<const void> model;
    uint64_t bytes = 0;  // what keeping it costs
  };
  using ParseFn = std::function<absl::StatusOr<Parsed>(const ParseCheck& check)>;

  explicit LoadedModels(const LoadedModelsOptions& options = {});
  ~LoadedModels();  // stops the parses and joins the threads
  LoadedModels(const LoadedModels&) = delete;
  LoadedModels& operator=(const LoadedModels&) = delete;

  // The model under `key`, parsed by `parse` on a parse thread if not kept.
  // `caller` (may be empty) is asked while the request waits; its non-OK
  // status ends the wait with that status (the parse goes on while another
  // request waits for it). `parse` must own what it uses. `working_bytes`:
  // the most memory the parse may use at once (an upper estimate).
  template <typename Model>
  absl::StatusOr<std::shared_ptr<const Model>> Get(const std::string& key, ParseFn parse,
                                                   const std::function<absl::Status()>& caller,
                                                   uint64_t working_bytes) {
    auto any = GetAny(key, std::move(parse), caller, working_bytes);
    if (!any.ok()) return any.status();
    return std::static_pointer_cast<const Model>(*std::move(any));
  }

  // Drops the kept parses and remembered failures of the model whose bytes
  // have SHA-256 `sha256` (keys holding "sha256=<hex>"): an evicted upload,
  // or a model whose request failed.
  void ForgetModel(const std::string& sha256) ABSL_LOCKS_EXCLUDED(mu_);

  LoadedModelsStats stats() const ABSL_LOCKS_EXCLUDED(mu_);
  const LoadedModelsOptions& options() const { return options_; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Job {
    std::string key;
    ParseFn parse;
    uint64_t working_bytes = 0;
    int passed_over = 0;  // guarded by mu_: smaller parses started before it
    int waiters = 0;  // guarded by mu_
    bool started = false;  // guarded by mu_
    bool long_parse = false;  // guarded by mu_: past fresh_seconds, counted in long_parses
    bool busy = false;  // guarded by mu_: stopped for load, not for the model: not remembered
    bool evicted = false;  // guarded by mu_: a smaller parse took its place among the long ones
    bool done = false;
    absl::StatusOr<Parsed> result;
  };
  struct Failure {
    absl::Status status;
    Clock::time_point when;
  };

  absl::StatusOr<std::shared_ptr<const void>> GetAny(const std::string& key, ParseFn parse,
                                                     const std::function<absl::Status()>& caller,
                                                     uint64_t working_bytes)
      ABSL_LOCKS_EXCLUDED(mu_);
  void ParserLoop() ABSL_LOCKS_EXCLUDED(mu_);
  // Runs a started job's parse on this thread and publishes its result.
  // REQUIRES: the job was taken off the queue (or never queued) and counted in
  // stats_.parsing and working_bytes_.
  // `caller`: the parsing request's own check (parse_threads == 0), asked
  // with the others; may be empty.
  void RunJob(const std::shared_ptr<Job>& job, const std::function<absl::Status()>& caller)
      ABSL_LOCKS_EXCLUDED(mu_);
  void Keep(const std::string& key, const Parsed& parsed) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Index in queue_ of the parse to start next. REQUIRES: !queue_.empty().
  size_t NextJob() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  static constexpr int kMaxPassedOver = 8;

  // Constant after construction.
  const LoadedModelsOptions options_;

  mutable absl::Mutex mu_;
  Lru<std::string, Parsed> kept_ ABSL_GUARDED_BY(mu_);  // by key, costing Parsed::bytes
  std::unordered_map<std::string, std::shared_ptr<Job>> pending_ ABSL_GUARDED_BY(mu_);
  std::deque<std::shared_ptr<Job>> queue_ ABSL_GUARDED_BY(mu_);
  std::unordered_map<std::string, Failure> failures_ ABSL_GUARDED_BY(mu_);
  uint64_t working_bytes_ ABSL_GUARDED_BY(mu_) = 0;  // reserved by running parses
  std::vector<std::shared_ptr<Job>> long_jobs_ ABSL_GUARDED_BY(mu_);  // running past fresh_seconds
  // Ends a queued job that will not run: its waiters get `status`.
  void DropQueued(const std::shared_ptr<Job>& job, absl::Status status)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  LoadedModelsStats stats_ ABSL_GUARDED_BY(mu_);  // models and bytes: see kept_
  std::vector<std::thread> threads_;  // started in the constructor, joined in the destructor
};

}  // namespace sfc

#endif  // SFCSAMPLER_ENGINE_LOADED_MODELS_H_
