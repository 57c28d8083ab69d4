// Helpers shared by the tests: build a sampler from catalogue specs and read
// whole index ranges.
#ifndef SFCSAMPLER_TESTS_TEST_UTIL_H_
#define SFCSAMPLER_TESTS_TEST_UTIL_H_

#include <memory>
#include <string>

#include "catalog/catalog.h"
#include "core/sampler.h"
#include "gtest/gtest.h"

namespace sfc::testing {

struct Setup {
  std::shared_ptr<const Surface> surface;
  std::shared_ptr<const Density> density;
  std::shared_ptr<const CurveTree> tree;
};

inline Setup MakeSetup(const std::string& surface, const std::string& density, uint64_t count,
                       CurveTreeOptions options = {}) {
  Setup s;
  auto sf = MakeSurface(surface);
  EXPECT_TRUE(sf.ok()) << sf.status();
  auto df = MakeDensity(density);
  EXPECT_TRUE(df.ok()) << df.status();
  s.surface = sf->surface;
  s.density = df->density;
  auto tree = CurveTree::Build(*s.surface, *s.density, options, CurveTree::GradeFor(count));
  EXPECT_TRUE(tree.ok()) << tree.status();
  s.tree = *tree;
  return s;
}

inline std::shared_ptr<const Sampler> MakeSampler(const Setup& s, SequenceKind kind, uint64_t count,
                                                  uint64_t seed) {
  return std::make_shared<const Sampler>(s.tree, s.surface, s.density, Sequence(kind, count, seed));
}

// All samples of [begin, end) inside `region`, read in batches of `batch`.
inline SampleBatch Collect(std::shared_ptr<const Sampler> sampler, uint64_t begin, uint64_t end,
                           const Region& region = {}, SampleFields fields = {},
                           size_t batch = 1000) {
  SampleBatch all;
  auto cursor = SampleCursor::Create(std::move(sampler), begin, end, region, fields);
  EXPECT_TRUE(cursor.ok()) << cursor.status();
  if (!cursor.ok()) return all;
  while (true) {
    auto n = (*cursor)->Next(batch, &all);
    EXPECT_TRUE(n.ok()) << n.status();
    if (!n.ok() || *n == 0) break;
  }
  return all;
}

// The same samples, bit for bit, in the same order.
inline void ExpectSameSamples(const SampleBatch& a, const SampleBatch& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.index[i], b.index[i]) << i;
    ASSERT_EQ(a.u[i], b.u[i]) << i;
    ASSERT_EQ(a.v[i], b.v[i]) << i;
    ASSERT_EQ(a.x[i], b.x[i]) << i;
    ASSERT_EQ(a.y[i], b.y[i]) << i;
    ASSERT_EQ(a.z[i], b.z[i]) << i;
  }
}

// The samples of `full` inside `region`, in order.
inline SampleBatch Filter(const SampleBatch& full, const Region& region) {
  SampleBatch out;
  for (size_t i = 0; i < full.size(); ++i) {
    if (region.Contains(full.u[i], full.v[i], {full.x[i], full.y[i], full.z[i]})) {
      out.AppendFrom(full, i, i + 1);
    }
  }
  return out;
}

}  // namespace sfc::testing

#endif  // SFCSAMPLER_TESTS_TEST_UTIL_H_
