#include "server/tree_cache.h"

#include <new>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace sfc {
namespace {

// How often a waiting request asks its own check (client gone, deadline).
constexpr absl::Duration kWaitPoll = absl::Milliseconds(50);

// Statuses that say the build was stopped, not that the tree cannot be built:
// these are not remembered as failures.
bool IsStop(const absl::Status& s) {
  return absl::IsCancelled(s) || absl::IsUnavailable(s) || absl::IsDeadlineExceeded(s);
}

}  // namespace

TreeCache::TreeCache(const TreeCacheOptions& options, std::function<void(double)> on_build)
    : options_(options), on_build_(std::move(on_build)) {
  const int threads = std::max(1, options_.max_concurrent_builds);
  for (int i = 0; i < threads; ++i) builders_.emplace_back([this] { BuilderLoop(); });
}

TreeCache::~TreeCache() { Stop(); }

absl::StatusOr<TreeLookup> TreeCache::Get(const TreeKey& key, int grade, const TreeFactory& factory,
                                          const BuildControl& caller) {
  const std::string id = absl::StrCat(key.canonical, "#g", grade);
  absl::MutexLock lock(&mu_);
  while (true) {
    if (const Entry* cached = cached_.Touch(id)) {
      ++stats_.hits;
      return TreeLookup{cached->tree, true, false};
    }
    if (auto it = retired_.find(id); it != retired_.end()) {
      // Evicted while a stream held it: take it back rather than build a copy.
      std::shared_ptr<const AnyTree> tree = it->second.tree.lock();
      const Retired retired = it->second;
      stats_.retired_bytes -= retired.bytes;
      retired_.erase(it);
      if (tree != nullptr) {
        ++stats_.revivals;
        ++stats_.hits;
        Insert(id, tree, retired.bytes, retired.canonical, retired.grade);
        EvictOverBudget();  // may retire it again at once: it is still held
        return TreeLookup{tree, true, false};
      }
    }
    if (stopping_) {
      return absl::UnavailableError(
          "the server is shutting down; retry on another replica or later");
    }
    if (auto it = failures_.find(id); it != failures_.end()) {
      const double age = std::chrono::duration<double>(Clock::now() - it->second.when).count();
      if (age < options_.failure_ttl_seconds) {
        ++stats_.failure_hits;
        const absl::Status& s = it->second.status;
        return absl::Status(s.code(),
                            absl::StrFormat("%s (this tree's build failed %.0f s ago; the "
                                            "server remembers failed builds for %g s)",
                                            s.message(), age, options_.failure_ttl_seconds));
      }
      failures_.erase(it);
    }
    std::shared_ptr<Job> job;
    if (auto it = pending_.find(id); it != pending_.end()) {
      ++stats_.waits;
      job = it->second;
    } else {
      // Jobs in queue_ that an idle builder is about to take do not count.
      const uint64_t idle = builders_.size() - stats_.builds_running;
      if (queue_.size() >= static_cast<uint64_t>(options_.max_queued_builds) + idle) {
        ++stats_.builds_rejected;
        return absl::ResourceExhaustedError(absl::StrFormat(
            "%d tree builds are running and %d more are queued, the server's limits "
            "(max_concurrent_builds, max_queued_builds); retry later",
            stats_.builds_running, queue_.size()));
      }
      ++stats_.misses;
      job = std::make_shared<Job>();
      job->id = id;
      job->canonical = key.canonical;
      job->grade = grade;
      job->factory = factory;
      if (auto g = grades_.find(key.canonical); g != grades_.end() && factory.refine) {
        auto below = g->second.lower_bound(grade);
        if (below != g->second.begin()) {
          job->coarser_grade = *std::prev(below);
          job->coarser = cached_.Find(absl::StrCat(key.canonical, "#g", job->coarser_grade))->tree;
        }
      }
      pending_.emplace(id, job);
      queue_.push_back(job);
    }
    ++job->waiters;

    // Wait for the job, asking the caller's own check now and then (outside
    // the lock: it may be slow or take other locks).
    while (!job->done) {
      mu_.AwaitWithTimeout(absl::Condition(&job->done), kWaitPoll);
      if (job->done || !caller.check) continue;
      mu_.Unlock();
      absl::Status still_wanted = caller.check();
      mu_.Lock();
      if (!still_wanted.ok() && !job->done) {
        // A running build notices at its next check; a queued one goes now.
        if (--job->waiters == 0 && !job->started) Forget(job);
        return still_wanted;
      }
    }
    --job->waiters;
    // Joined a build just as every earlier waiter gave up on it: start over.
    if (absl::IsCancelled(job->result.status())) continue;
    if (!job->result.ok()) return job->result.status();
    return TreeLookup{*job->result, false, job->coarser != nullptr};
  }
}

void TreeCache::Forget(const std::shared_ptr<Job>& job) {
  pending_.erase(job->id);
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (*it == job) {
      queue_.erase(it);
      break;
    }
  }
  ++stats_.builds_stopped;
}

void TreeCache::BuilderLoop() {
  while (true) {
    std::shared_ptr<Job> job;
    {
      absl::MutexLock lock(&mu_);
      auto has_work = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        return stopping_ || !queue_.empty();
      };
      mu_.Await(absl::Condition(&has_work));
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      job->started = true;
      ++stats_.builds_running;
    }
    Run(*job);
  }
}

absl::Status TreeCache::BuildCheck(const Job& job) const {
  absl::MutexLock lock(&mu_);
  if (stopping_) {
    return absl::UnavailableError("the server is shutting down; the tree build was stopped");
  }
  if (job.waiters == 0) {
    return absl::CancelledError(
        "every request waiting for this tree has gone; its build was stopped");
  }
  return absl::OkStatus();
}

absl::Status TreeCache::Charge(Job& job, uint64_t bytes) {
  absl::MutexLock lock(&mu_);
  stats_.building_bytes = stats_.building_bytes - job.charged + bytes;
  job.charged = bytes;
  while (true) {
    EvictOverBudget();
    if (stats_.building_bytes > options_.budget_bytes) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "the trees being built need more than the server's tree memory of %d bytes "
          "(cache_bytes): retry later, or ask for fewer samples",
          options_.budget_bytes));
    }
    // Room that evicted trees still held by streams take: wait for the
    // streams to end (a refinement's own coarser tree is not waited for).
    uint64_t retired = stats_.retired_bytes;
    if (job.coarser != nullptr) {
      if (auto it = retired_.find(absl::StrCat(job.canonical, "#g", job.coarser_grade));
          it != retired_.end() && it->second.raw == job.coarser.get()) {
        retired -= it->second.bytes;
      }
    }
    if (stats_.building_bytes + retired <= options_.budget_bytes) return absl::OkStatus();
    if (stopping_) {
      return absl::UnavailableError("the server is shutting down; the tree build was stopped");
    }
    if (job.waiters == 0) {
      return absl::CancelledError(
          "every request waiting for this tree has gone; its build was stopped");
    }
    ++stats_.retired_waits;
    mu_.Unlock();
    absl::SleepFor(kWaitPoll);
    mu_.Lock();
  }
}

void TreeCache::Run(Job& job) {
  BuildControl control{[this, &job] { return BuildCheck(job); },
                       [this, &job](uint64_t bytes) { return Charge(job, bytes); }};
  const auto start = Clock::now();
  Result result = absl::InternalError("the tree build did not run");
  try {
    result = job.coarser ? job.factory.refine(*job.coarser, job.grade, control)
                         : job.factory.build(job.grade, control);
  } catch (const std::bad_alloc&) {
    result = absl::ResourceExhaustedError(
        "the server ran out of memory building this tree; ask for fewer samples, a coarser "
        "tolerance, or retry when the server is less busy");
  } catch (const std::exception& e) {
    result = absl::InternalError(absl::StrCat("the tree build failed: ", e.what()));
  }
  if (result.ok()) {
    // The build's charges lag its growth: the finished tree takes its exact
    // room before it enters the cache (and waits, like a growing build, for
    // room that held evicted trees take).
    if (absl::Status room = Charge(job, (*result)->bytes()); !room.ok()) result = room;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  {
    absl::MutexLock lock(&mu_);
    Finish(job, std::move(result), seconds);
  }
  if (on_build_) on_build_(seconds);
}

void TreeCache::Finish(Job& job, Result result, double seconds) {
  --stats_.builds_running;
  stats_.building_bytes -= job.charged;
  job.charged = 0;
  pending_.erase(job.id);
  stats_.build_seconds += seconds;
  if (result.ok()) {
    ++(job.coarser ? stats_.refinements : stats_.builds);
    Insert(job.id, *result, (*result)->bytes(), job.canonical, job.grade);
    EvictOverBudget();
  } else if (IsStop(result.status())) {
    ++stats_.builds_stopped;
  } else {
    ++stats_.builds_failed;
    // Bounded: expired failures go first, then the oldest.
    constexpr size_t kMaxFailures = 4096;
    if (failures_.size() >= kMaxFailures) {
      const auto now = Clock::now();
      for (auto it = failures_.begin(); it != failures_.end();) {
        const bool expired = std::chrono::duration<double>(now - it->second.when).count() >=
                             options_.failure_ttl_seconds;
        it = expired ? failures_.erase(it) : std::next(it);
      }
      if (failures_.size() >= kMaxFailures) failures_.erase(failures_.begin());
    }
    if (options_.failure_ttl_seconds > 0)
      failures_[job.id] = Failure{result.status(), Clock::now()};
  }
  job.result = std::move(result);
  job.done = true;
}

void TreeCache::Stop() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
    for (const std::shared_ptr<Job>& job : queue_) {
      pending_.erase(job->id);
      job->result =
          absl::UnavailableError("the server is shutting down; retry on another replica or later");
      job->done = true;
      ++stats_.builds_stopped;
    }
    queue_.clear();
  }
  for (std::thread& t : builders_) {
    if (t.joinable()) t.join();
  }
}

void TreeCache::Insert(const std::string& id, std::shared_ptr<const AnyTree> tree, uint64_t bytes,
                       const std::string& canonical, int grade) {
  cached_.Insert(id, Entry{std::move(tree), canonical, grade}, bytes);
  grades_[canonical].insert(grade);
}

void TreeCache::PruneRetired() {
  for (auto it = retired_.begin(); it != retired_.end();) {
    if (it->second.tree.expired()) {
      stats_.retired_bytes -= it->second.bytes;
      it = retired_.erase(it);
    } else {
      ++it;
    }
  }
}

void TreeCache::EvictOverBudget() {
  PruneRetired();
  // A retired tree's bytes still count: evicting it frees no room.
  while (cached_.total_cost() + stats_.building_bytes + stats_.retired_bytes >
             options_.budget_bytes &&
         !cached_.empty()) {
    Lru<std::string, Entry>::Entry evicted = cached_.PopLeastRecent();
    const Entry& entry = evicted.value;
    auto grades = grades_.find(entry.canonical);
    grades->second.erase(entry.grade);
    if (grades->second.empty()) grades_.erase(grades);
    if (entry.tree.use_count() > 1) {  // a stream or a refinement holds it
      stats_.retired_bytes += evicted.cost;
      retired_[evicted.key] = Retired{entry.tree, entry.tree.get(), evicted.cost, entry.canonical,
                                      entry.grade};
    }
    ++stats_.evictions;
  }
}

TreeCacheStats TreeCache::stats() const {
  absl::MutexLock lock(&mu_);
  TreeCacheStats s = stats_;
  s.entries = cached_.size();
  s.bytes = cached_.total_cost();
  s.retired_bytes = s.retired_trees = 0;  // those still held now
  for (const auto& [id, retired] : retired_) {
    if (retired.tree.expired()) continue;
    s.retired_bytes += retired.bytes;
    ++s.retired_trees;
  }
  s.builds_queued = queue_.size();
  return s;
}

}  // namespace sfc
