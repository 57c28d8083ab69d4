// A batch of samples as a structure of arrays, in curve order.
// Value type; thread-compatible.
#ifndef SFCSAMPLER_CORE_SAMPLE_BATCH_H_
#define SFCSAMPLER_CORE_SAMPLE_BATCH_H_

#include <cstdint>
#include <vector>

namespace sfc {

// Optional per-sample columns.
struct SampleFields {
  bool normal = false;          // unit normal (nx, ny, nz)
  bool density = false;         // delta at the sample
  bool curve_position = false;  // position along the parameter-space curve, in [0,1)
};

struct SampleBatch {
  std::vector<uint64_t> index;  // the sample's index k in the set
  std::vector<double> u, v;     // unit-square parameters
  std::vector<double> x, y, z;  // f(u, v)
  std::vector<double> nx, ny, nz;
  std::vector<double> density;
  std::vector<double> curve_position;

  size_t size() const { return index.size(); }
  void Clear() {
    for (auto* c : {&u, &v, &x, &y, &z, &nx, &ny, &nz, &density, &curve_position}) c->clear();
    index.clear();
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_SAMPLE_BATCH_H_
