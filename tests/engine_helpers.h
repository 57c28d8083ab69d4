// Helpers shared by the engine's tests (engine_mesh_test, engine_cad_test,
// blue_sequence_test).
#ifndef SFCSAMPLER_TESTS_ENGINE_HELPERS_H_
#define SFCSAMPLER_TESTS_ENGINE_HELPERS_H_

#include <fstream>
#include <string>

#include "engine/model_source.h"
#include "engine/sampling_engine.h"
#include "engine/tree_source.h"
#include "gtest/gtest.h"
#include "kinds/registered_kinds.h"

namespace sfc {

// Writes `bytes` to a file called `name` in the test's temporary directory
// and returns its path.
inline std::string WriteTemp(const std::string& name, const std::string& bytes) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// An engine in process with `threads` generation threads, trees built per
// request and model files read from disk.
struct LocalEngine {
  DirectTreeSource source;
  FileModelSource files;
  SamplingEngine engine;
  explicit LocalEngine(int threads = 1)
      : engine(RegisteredSurfaceKinds(), Limits(threads), &source, &files) {}
  static EngineLimits Limits(int threads) {
    EngineLimits limits;
    limits.generation_threads = threads;
    return limits;
  }
};

// Every sample of `r`, read in batches of 5000; a failure is a test failure.
inline SampleBatch DrawAll(const SamplingEngine& engine, const SampleRequest& r) {
  auto job = engine.Start(r);
  EXPECT_TRUE(job.ok()) << job.status();
  SampleBatch all;
  if (!job.ok()) return all;
  while (true) {
    auto n = job->cursor->Next(5000, &all);
    EXPECT_TRUE(n.ok()) << n.status();
    if (!n.ok() || *n == 0) break;
  }
  return all;
}

}  // namespace sfc

#endif  // SFCSAMPLER_TESTS_ENGINE_HELPERS_H_
