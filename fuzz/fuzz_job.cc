#include "fuzz/fuzz_job.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include "kinds/registered_kinds.h"
#include "request/index_range.h"

namespace sfc::fuzz {
namespace {

[[noreturn]] void Fail(const char* what, const SampleRequest& r) {
  std::fprintf(stderr,
               "fuzz: %s\n  surface=\"%s\" density=\"%s\" count=%llu tree_count=%llu begin=%llu "
               "end=%llu shard=%llu/%llu sequence=%d region=%d\n",
               what, r.tree.surface.c_str(), r.tree.density.c_str(),
               static_cast<unsigned long long>(r.count),
               static_cast<unsigned long long>(r.tree_count),
               static_cast<unsigned long long>(r.begin), static_cast<unsigned long long>(r.end),
               static_cast<unsigned long long>(r.shard_index),
               static_cast<unsigned long long>(r.shard_count), static_cast<int>(r.sequence),
               static_cast<int>(r.region.kind));
  __builtin_trap();
}

// Bad input must come back as INVALID_ARGUMENT or RESOURCE_EXHAUSTED with a
// message that says what to fix.
void CheckError(const absl::Status& status, const SampleRequest& r) {
  if (status.code() != absl::StatusCode::kInvalidArgument &&
      status.code() != absl::StatusCode::kResourceExhausted) {
    std::fprintf(stderr, "fuzz: status %s\n", status.ToString().c_str());
    Fail("an error other than INVALID_ARGUMENT or RESOURCE_EXHAUSTED", r);
  }
  if (status.message().empty()) Fail("an error without a message", r);
}

}  // namespace

EngineLimits SmallLimits() {
  EngineLimits limits;
  limits.max_count = 4096;
  limits.max_tree_leaves = 4096;
  limits.max_spec_length = 512;
  limits.max_sorted_range = 4096;
  limits.generation_threads = 1;
  return limits;
}

void CheckRequest(const SampleRequest& request) {
  static DirectTreeSource* const source = new DirectTreeSource;
  static FileModelSource* const files = new FileModelSource;
  static const SamplingEngine* const engine =
      new SamplingEngine(RegisteredSurfaceKinds(), SmallLimits(), source, files);

  const auto range = ResolveIndexRange(request);
  if (!range.ok()) CheckError(range.status(), request);
  auto job = engine->Start(request);
  if (!job.ok()) {
    CheckError(job.status(), request);
    return;
  }
  if (!range.ok()) Fail("Start accepted a request whose range ResolveRange rejects", request);
  if (job->begin != range->first || job->end != range->second) {
    Fail("Start resolved another range than ResolveRange", request);
  }
  if (job->begin > job->end || job->end > request.count)
    Fail("a range outside [0, count)", request);

  std::vector<bool> seen(job->end - job->begin, false);
  uint64_t emitted = 0;
  double last_position = -1;
  SampleBatch batch;
  for (;;) {
    batch.Clear();
    auto n = job->cursor->Next(1000, &batch);
    if (!n.ok()) {
      CheckError(n.status(), request);
      return;
    }
    if (*n == 0) break;
    if (batch.size() != *n) Fail("Next() reported another count than it appended", request);
    for (size_t i = 0; i < batch.size(); ++i) {
      const uint64_t k = batch.index[i];
      if (k < job->begin || k >= job->end) Fail("a sample index outside the range", request);
      if (seen[k - job->begin]) Fail("a sample index twice", request);
      seen[k - job->begin] = true;
      if (!(batch.u[i] >= 0 && batch.u[i] <= 1 && batch.v[i] >= 0 && batch.v[i] <= 1)) {
        Fail("parameters outside the unit square", request);
      }
      if (!std::isfinite(batch.x[i]) || !std::isfinite(batch.y[i]) || !std::isfinite(batch.z[i])) {
        Fail("a non-finite sample was emitted", request);
      }
      if (!request.region.Contains(batch.u[i], batch.v[i], {batch.x[i], batch.y[i], batch.z[i]})) {
        Fail("a sample outside the requested region", request);
      }
      if (request.fields.curve_position) {
        if (batch.curve_position[i] < last_position) Fail("samples out of curve order", request);
        last_position = batch.curve_position[i];
      }
    }
    emitted += batch.size();
  }
  if (request.region.kind == Region::Kind::kAll && emitted != job->end - job->begin) {
    Fail("a request without a region lost or added samples", request);
  }
}

}  // namespace sfc::fuzz
