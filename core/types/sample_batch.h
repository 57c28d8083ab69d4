// A batch of samples as a structure of arrays, in curve order.
// Value type; thread-compatible.
#ifndef SFCSAMPLER_CORE_TYPES_SAMPLE_BATCH_H_
#define SFCSAMPLER_CORE_TYPES_SAMPLE_BATCH_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sfc {

// Optional per-sample columns. The engine always fills u, v, x, y and z;
// `uv` and `xyz` say whether they travel on the wire (a client that writes
// only some columns leaves the others off; proto/convert.h).
struct SampleFields {
  bool uv = true;               // u, v
  bool xyz = true;              // x, y, z
  bool normal = false;          // unit normal (nx, ny, nz)
  bool density = false;         // delta at the sample
  bool curve_position = false;  // position along the parameter-space curve, in [0,1)
  bool face = false;            // CAD models: the sample's face, 0-based in the file's order
  bool triangle = false;        // meshes: the sample's triangle, 0-based in the file's order
};

struct SampleBatch {
  std::vector<uint64_t> index;  // the sample's index k in the set
  std::vector<double> u, v;     // unit-square parameters
  std::vector<double> x, y, z;  // f(u, v)
  std::vector<double> nx, ny, nz;
  std::vector<double> density;
  std::vector<double> curve_position;
  std::vector<uint32_t> face;
  std::vector<uint32_t> triangle;

  size_t size() const { return index.size(); }

  // The float columns as members: u v x y z nx ny nz density curve_position.
  using ValueColumn = std::vector<double> SampleBatch::*;
  static const std::array<ValueColumn, 10>& ValueColumns() {
    static constexpr std::array<ValueColumn, 10> kColumns = {
        &SampleBatch::u,       &SampleBatch::v,
        &SampleBatch::x,       &SampleBatch::y,
        &SampleBatch::z,       &SampleBatch::nx,
        &SampleBatch::ny,      &SampleBatch::nz,
        &SampleBatch::density, &SampleBatch::curve_position};
    return kColumns;
  }

  // Appends samples [begin, end) of `other`, with whichever optional columns
  // `other` has. REQUIRES: begin <= end <= other.size(), and this batch has the
  // same optional columns (or is empty).
  void AppendFrom(const SampleBatch& other, size_t begin, size_t end) {
    index.insert(index.end(), other.index.begin() + begin, other.index.begin() + end);
    for (ValueColumn column : ValueColumns()) {
      const std::vector<double>& from = other.*column;
      if (from.empty()) continue;
      std::vector<double>& to = this->*column;
      to.insert(to.end(), from.begin() + begin, from.begin() + end);
    }
    for (auto column : {&SampleBatch::face, &SampleBatch::triangle}) {
      const std::vector<uint32_t>& from = other.*column;
      if (from.empty()) continue;
      std::vector<uint32_t>& to = this->*column;
      to.insert(to.end(), from.begin() + begin, from.begin() + end);
    }
  }
  void Append(const SampleBatch& other) { AppendFrom(other, 0, other.size()); }
  // f(&column) for every column a batch with `fields` holds: index, u, v, x,
  // y and z always, then nx ny nz, density, curve_position, face and
  // triangle as `fields` ask. The one list of them: the cursor grows and
  // truncates by it, and Python's embedded path takes its buffers by it.
  template <class F>
  void ForEachColumn(const SampleFields& fields, F&& f) {
    f(&index);
    for (auto* column : {&u, &v, &x, &y, &z}) f(column);
    if (fields.normal) {
      for (auto* column : {&nx, &ny, &nz}) f(column);
    }
    if (fields.density) f(&density);
    if (fields.curve_position) f(&curve_position);
    if (fields.face) f(&face);
    if (fields.triangle) f(&triangle);
  }
  void Clear() {
    for (ValueColumn column : ValueColumns()) (this->*column).clear();
    index.clear(), face.clear(), triangle.clear();
  }
};

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_TYPES_SAMPLE_BATCH_H_
