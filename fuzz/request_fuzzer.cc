// libFuzzer target: the engine's request checks (SamplingEngine::ResolveRange
// and Start) on requests assembled field by field from the input, then every
// accepted request run to its last sample (fuzz/fuzz_job.h). Specs come from a
// short list of valid ones or from the input's bytes.
#include <cstddef>
#include <cstdint>
#include <string>

#include <fuzzer/FuzzedDataProvider.h>

#include "fuzz/fuzz_job.h"

namespace {

constexpr const char* kSurfaces[] = {
    "plane", "sphere", "torus:R=2;r=0.5", "monkey_saddle", "eight", "whitney",
    "superellipsoid:e=1/3;reparam=1", "expr:x=u;y=v;z=u*v",
    "expr:x=cos(u)*cos(v);y=cos(u)*sin(v);z=sin(u);u0=-_pi/2;u1=_pi/2;v0=-_pi;v1=_pi"};
constexpr const char* kDensities[] = {"uniform", "gaussian:floor=0.05", "mean", "expr:u+v",
                                      "expr:x*x+y*y", "expr:1/u"};

// A uint64 that is often small, sometimes near a limit, sometimes anything.
uint64_t Count(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: return in.ConsumeIntegralInRange<uint64_t>(0, 64);
    case 1: return in.ConsumeIntegralInRange<uint64_t>(0, 5000);
    case 2: return in.ConsumeIntegralInRange<uint64_t>(4090, 4100);
    default: return in.ConsumeIntegral<uint64_t>();
  }
}

std::string Spec(FuzzedDataProvider& in, const char* const* list, size_t n) {
  if (in.ConsumeBool()) return list[in.ConsumeIntegralInRange<size_t>(0, n - 1)];
  return in.ConsumeRandomLengthString(128);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  sfc::SampleRequest r;
  r.tree.surface = Spec(in, kSurfaces, std::size(kSurfaces));
  r.tree.density = Spec(in, kDensities, std::size(kDensities));
  r.tree.options.curve = in.PickValueInArray(
      {sfc::CurveType::kHilbert, sfc::CurveType::kHilbert2, sfc::CurveType::kPeano});
  r.tree.options.estimator = in.PickValueInArray(
      {sfc::AreaEstimator::kFirstFundamentalForm, sfc::AreaEstimator::kTriangle,
       sfc::AreaEstimator::kSquare, sfc::AreaEstimator::kQuadrature});
  if (in.ConsumeBool()) r.tree.options.tolerance = in.ConsumeFloatingPoint<double>();
  if (in.ConsumeBool()) r.tree.options.depth_cap = in.ConsumeIntegral<int>();
  if (in.ConsumeBool()) r.tree.options.rho = in.ConsumeFloatingPoint<double>();
  r.sequence = in.PickValueInArray({sfc::SequenceKind::kJittered, sfc::SequenceKind::kEqual,
                                    sfc::SequenceKind::kRandom, sfc::SequenceKind::kVanDerCorput,
                                    sfc::SequenceKind::kProgressive, sfc::SequenceKind::kSobol});
  r.count = Count(in);
  r.seed = in.ConsumeIntegral<uint64_t>();
  if (in.ConsumeBool()) r.tree_count = Count(in);
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0: break;
    case 1:
      r.begin = Count(in);
      r.end = Count(in);
      break;
    default:
      r.shard_index = Count(in);
      r.shard_count = Count(in);
      if (in.ConsumeBool()) r.begin = Count(in);
      break;
  }
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0: break;
    case 1: {
      const double u0 = in.ConsumeFloatingPoint<double>(), u1 = in.ConsumeFloatingPoint<double>();
      const double v0 = in.ConsumeFloatingPoint<double>(), v1 = in.ConsumeFloatingPoint<double>();
      r.region = sfc::Region::ParameterRect(u0, u1, v0, v1);
      break;
    }
    default: {
      sfc::Vec3 lo, hi;
      for (double* c : {&lo.x, &lo.y, &lo.z, &hi.x, &hi.y, &hi.z})
        *c = in.ConsumeFloatingPoint<double>();
      r.region = sfc::Region::Box(lo, hi);
      break;
    }
  }
  r.fields.normal = in.ConsumeBool();
  r.fields.density = in.ConsumeBool();
  r.fields.curve_position = in.ConsumeBool();
  sfc::fuzz::CheckRequest(r);
  return 0;
}
