#include "engine/loaded_models.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <time.h>

#include <algorithm>
#include <atomic>

#include <exception>
#include <new>

#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "absl/time/time.h"

namespace sfc {
namespace {

// The parse threads' nice value (Linux: per thread), below the RPC threads'.
constexpr int kParseNice = 10;

// CPU seconds of the thread whose CPU clock is `clock`.
double CpuSeconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

absl::Status ParseBudgetSpent(double seconds) {
  return absl::ResourceExhaustedError(absl::StrFormat(
      "reading the model took more than %g s of CPU and was stopped (model_parse_seconds: "
      "--model-parse-seconds of sample, inspect, sample-many or the server, whose budget for a "
      "CAD file is at most 2 s + --model-parse-seconds-per-mib a MiB of it): simplify the model "
      "(fewer or simpler faces), or raise the limit",
      seconds));
}

LoadedModels::LoadedModels(const LoadedModelsOptions& options)
    : options_([&options] {
        LoadedModelsOptions o = options;
        o.parse_threads = std::max(0, o.parse_threads);
        return o;
      }()) {
  // A thread for each slot, and one for each long parse that left its slot.
  const int threads = options_.parse_threads +
                      (options_.parse_threads > 0 && options_.fresh_seconds > 0
                           ? std::max(0, options_.max_long_parses)
                           : 0);
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { ParserLoop(); });
}

LoadedModels::~LoadedModels() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  for (std::thread& t : threads_) t.join();
}

absl::StatusOr<std::shared_ptr<const void>> LoadedModels::GetAny(
    const std::string& key, ParseFn parse, const std::function<absl::Status()>& caller,
    uint64_t working_bytes) {
  std::shared_ptr<Job> job;
  bool parse_here = false;  // parse_threads == 0: this thread parses
  {
    absl::MutexLock lock(&mu_);
    if (const Parsed* kept = kept_.Touch(key)) {
      ++stats_.hits;
      return kept->model;
    }
    if (auto it = failures_.find(key); it != failures_.end()) {
      const double age = std::chrono::duration<double>(Clock::now() - it->second.when).count();
      if (age <= options_.failure_ttl_seconds) {
        ++stats_.failure_hits;
        return it->second.status;
      }
      failures_.erase(it);
    }
    if (stopping_) return absl::UnavailableError("the server is shutting down");
    if (auto it = pending_.find(key); it != pending_.end()) {
      job = it->second;
    } else if (options_.working_budget_bytes > 0 && working_bytes > options_.working_budget_bytes) {
      ++stats_.parses_rejected;
      return absl::ResourceExhaustedError(absl::StrFormat(
          "parsing this model needs up to %d bytes of memory (estimated from its size), more than "
          "this server gives parses (parse_memory_bytes %d); simplify or split the model, or ask "
          "the operator to raise the limit",
          working_bytes, options_.working_budget_bytes));
    } else {
      parse_here = options_.parse_threads == 0;
      if (!parse_here &&
          queue_.size() >= static_cast<size_t>(std::max(0, options_.max_queued_parses))) {
        // A full queue takes a smaller parse in place of its largest.
        auto largest = std::max_element(
            queue_.begin(), queue_.end(),
            [](const auto& a, const auto& b) { return a->working_bytes < b->working_bytes; });
        if (largest == queue_.end() || (*largest)->working_bytes <= working_bytes) {
          ++stats_.parses_rejected;
          ++stats_.parses_busy;
          return absl::ResourceExhaustedError(absl::StrFormat(
              "%d model parses are already waiting for a parser (max_queued_parses); retry later",
              queue_.size()));
        }
        const std::shared_ptr<Job> pushed = *largest;
        queue_.erase(largest);
        DropQueued(pushed, absl::ResourceExhaustedError(
                               "the server's model parse queue is full and smaller models took "
                               "this one's place (max_queued_parses); retry later"));
      }
      job = std::make_shared<Job>();
      job->key = key;
      job->parse = std::move(parse);
      job->working_bytes = working_bytes;
      pending_.emplace(key, job);
      if (parse_here) {  // started at once, as ParserLoop starts a queued one
        ++stats_.parsing;
        job->started = true;
        working_bytes_ += working_bytes;
      } else {
        queue_.push_back(job);
      }
    }
    ++job->waiters;
  }
  if (parse_here) RunJob(job, caller);
  // Wait in short steps, asking the caller between them.
  const Clock::time_point queued_at = Clock::now();
  while (true) {
    absl::Status wanted = caller ? caller() : absl::OkStatus();
    absl::MutexLock lock(&mu_);
    if (job->done) {
      --job->waiters;
      // A parse stopped because this request left says why it left.
      if (!job->result.ok()) return wanted.ok() ? job->result.status() : wanted;
      return job->result->model;
    }
    if (wanted.ok() && !job->started && options_.max_queue_wait_seconds > 0 &&
        std::chrono::duration<double>(Clock::now() - queued_at).count() >
            options_.max_queue_wait_seconds) {
      ++stats_.parses_busy;
      wanted = absl::ResourceExhaustedError(absl::StrFormat(
          "this model waited %g s for a parser while the server parsed others "
          "(max_queue_wait_seconds); retry later",
          options_.max_queue_wait_seconds));
    }
    if (!wanted.ok()) {
      --job->waiters;  // a queued job nobody waits for is dropped when its turn comes
      return wanted;
    }
    mu_.AwaitWithTimeout(absl::Condition(&job->done), absl::Milliseconds(50));
  }
}

void LoadedModels::ParserLoop() {
  // Parses yield the CPU to the threads that serve requests: one hostile
  // model on every parse thread must not slow other clients' samples.
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kParseNice);
  while (true) {
    std::shared_ptr<Job> job;
    {
      absl::MutexLock lock(&mu_);
      // The next parse (NextJob) starts when a slot is free (long parses hold
      // none) and its working memory fits beside the running parses' (or
      // nothing runs).
      auto ready = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        if (stopping_) return true;
        if (queue_.empty()) return false;
        if (stats_.parsing - stats_.long_parses >= static_cast<uint64_t>(options_.parse_threads)) {
          return false;
        }
        return working_bytes_ == 0 || options_.working_budget_bytes == 0 ||
               working_bytes_ + queue_[NextJob()]->working_bytes <= options_.working_budget_bytes;
      };
      mu_.Await(absl::Condition(&ready));
      if (stopping_) {
        // Nobody is parsed any more: queued requests get UNAVAILABLE.
        for (auto& queued : queue_) {
          queued->result = absl::UnavailableError("the server is shutting down");
          queued->done = true;
          pending_.erase(queued->key);
        }
        queue_.clear();
        return;
      }
      const size_t next = NextJob();
      for (size_t i = 0; i < next; ++i) ++queue_[i]->passed_over;
      job = queue_[next];
      queue_.erase(queue_.begin() + static_cast<std::ptrdiff_t>(next));
      if (job->waiters == 0) {  // every request left while it was queued
        job->result = absl::CancelledError("no request waits for this model any more");
        job->done = true;
        pending_.erase(job->key);
        ++stats_.parses_stopped;
        continue;
      }
      ++stats_.parsing;
      job->started = true;
      working_bytes_ += job->working_bytes;
    }
    RunJob(job, nullptr);
  }
}

void LoadedModels::RunJob(const std::shared_ptr<Job>& job,
                          const std::function<absl::Status()>& caller) {
  // The parse thread's CPU clock: a parser may call the check from its own
  // helper threads, so it is thread-safe and reads this thread's clock.
  clockid_t cpu_clock = CLOCK_THREAD_CPUTIME_ID;
  if (pthread_getcpuclockid(pthread_self(), &cpu_clock) != 0) cpu_clock = CLOCK_THREAD_CPUTIME_ID;
  const double cpu_start = CpuSeconds(cpu_clock);
  const Clock::time_point wall_start = Clock::now();
  // Slots exist for parses on this object's threads only.
  const bool may_turn_long = options_.parse_threads > 0 && options_.fresh_seconds > 0;
  std::atomic<uint64_t> calls{0};
  absl::Mutex stop_mu;
  absl::Status stop;  // sticky once set; guarded by stop_mu
  const ParseCheck check = [&]() -> absl::Status {
    // Called often by the parsers: the locks and the clock every 64th time.
    if ((calls.fetch_add(1, std::memory_order_relaxed) & 63) != 0) {
      absl::MutexLock l(&stop_mu);
      return stop;
    }
    absl::Status now;
    {
      absl::MutexLock lock(&mu_);
      if (stopping_) {
        now = absl::UnavailableError("the server is shutting down");
      } else if (job->waiters == 0) {
        now = absl::CancelledError("no request waits for this model any more");
      } else if (job->evicted) {
        now = absl::ResourceExhaustedError(absl::StrFormat(
            "parsing this model took more than %g s, and smaller models needed its place among "
            "the %d long parses the server runs at once (max_long_parses); it was stopped: "
            "retry later",
            options_.fresh_seconds, options_.max_long_parses));
      } else if (may_turn_long && !job->long_parse &&
                 std::chrono::duration<double>(Clock::now() - wall_start).count() >
                     options_.fresh_seconds) {
        // Past max_long_parses, the largest long parse is stopped: this one,
        // unless a running one is larger (it stops at its next check).
        const size_t limit = static_cast<size_t>(std::max(0, options_.max_long_parses));
        const size_t running_long = static_cast<size_t>(std::count_if(
            long_jobs_.begin(), long_jobs_.end(), [](const auto& j) { return !j->evicted; }));
        std::shared_ptr<Job> largest;
        if (running_long >= limit) {
          for (const auto& other : long_jobs_) {
            if (!other->evicted && other->working_bytes > job->working_bytes &&
                (!largest || other->working_bytes > largest->working_bytes)) {
              largest = other;
            }
          }
          if (largest) {
            largest->evicted = true;
            largest->busy = true;
          }
        }
        if (running_long < limit || largest) {
          job->long_parse = true;  // its slot is free: the next parse may start
          long_jobs_.push_back(job);
          ++stats_.long_parses;
        } else {
          job->busy = true;
          now = absl::ResourceExhaustedError(absl::StrFormat(
              "parsing this model takes more than %g s and the server is already parsing %d "
              "such models (max_long_parses); it was stopped: retry later",
              options_.fresh_seconds, options_.max_long_parses));
        }
      }
    }
    // Inline, the parsing request's own check too (its deadline, its client).
    // Stopped for it, the parse is not the model's fault: not remembered.
    if (now.ok() && caller && !caller().ok()) {
      now = absl::CancelledError("the request parsing this model left (its deadline passed or "
                                 "its client went); ask again");
    }
    const double spent = CpuSeconds(cpu_clock) - cpu_start;
    if (now.ok() && options_.parse_seconds > 0 && spent > options_.parse_seconds) {
      now = ParseBudgetSpent(options_.parse_seconds);
    }
    absl::MutexLock l(&stop_mu);
    if (stop.ok()) stop = now;
    return stop;
  };
  absl::StatusOr<Parsed> result;
  try {
    result = job->parse(check);
  } catch (const std::bad_alloc&) {
    result = absl::ResourceExhaustedError("out of memory while parsing the model");
  } catch (const std::exception& e) {
    result = absl::InternalError(absl::StrFormat("parsing the model failed: %s", e.what()));
  } catch (...) {  // whatever a parser throws, the job ends and its waiters hear of it
    result = absl::InternalError("parsing the model failed with an unknown exception");
  }
  {
    absl::MutexLock l(&stop_mu);
    if (result.ok() && !stop.ok()) result = stop;  // a parser that ignored the stop
  }
  absl::MutexLock lock(&mu_);
  --stats_.parsing;
  if (job->long_parse) {
    --stats_.long_parses;
    long_jobs_.erase(std::find(long_jobs_.begin(), long_jobs_.end(), job));
  }
  working_bytes_ -= job->working_bytes;
  ++stats_.parses;
  pending_.erase(job->key);
  if (result.ok()) {
    Keep(job->key, *result);
  } else if (job->busy) {
    ++stats_.parses_stopped;  // the server's load, not the model: the next request parses again
    ++stats_.parses_busy;
  } else if (result.status().code() == absl::StatusCode::kCancelled ||
             result.status().code() == absl::StatusCode::kUnavailable) {
    ++stats_.parses_stopped;  // not the model's fault: the next request parses again
  } else {
    if (result.status().code() == absl::StatusCode::kResourceExhausted) ++stats_.parses_stopped;
    failures_[job->key] = Failure{result.status(), Clock::now()};
    ++stats_.parse_failures;
  }
  job->result = std::move(result);
  job->done = true;
}

void LoadedModels::DropQueued(const std::shared_ptr<Job>& job, absl::Status status) {
  job->result = std::move(status);
  job->done = true;
  pending_.erase(job->key);
  ++stats_.parses_busy;
}

size_t LoadedModels::NextJob() const {
  if (queue_.front()->passed_over >= kMaxPassedOver) return 0;
  size_t next = 0;
  for (size_t i = 1; i < queue_.size(); ++i) {
    if (queue_[i]->working_bytes < queue_[next]->working_bytes) next = i;
  }
  return next;
}

void LoadedModels::Keep(const std::string& key, const Parsed& parsed) {
  if (parsed.bytes > options_.budget_bytes) return;  // returned to its requests, not kept
  if (!kept_.Insert(key, parsed, parsed.bytes)) return;  // kept already
  while (kept_.total_cost() > options_.budget_bytes && !kept_.empty()) {
    kept_.PopLeastRecent();
    ++stats_.evictions;
  }
}

void LoadedModels::ForgetModel(const std::string& sha256) {
  const std::string needle = "sha256=" + sha256;
  absl::MutexLock lock(&mu_);
  kept_.EraseIf([&needle](const std::string& key, const Parsed&) {
    return absl::StrContains(key, needle);
  });
  for (auto it = failures_.begin(); it != failures_.end();) {
    it = absl::StrContains(it->first, needle) ? failures_.erase(it) : std::next(it);
  }
}

LoadedModelsStats LoadedModels::stats() const {
  absl::MutexLock lock(&mu_);
  LoadedModelsStats s = stats_;
  s.models = kept_.size();
  s.bytes = kept_.total_cost();
  s.queued = queue_.size();
  s.working_bytes = working_bytes_;
  return s;
}

}  // namespace sfc
