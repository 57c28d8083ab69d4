#include "proto/convert.h"

#include "base/echo.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "absl/base/config.h"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"

namespace sfc {
namespace {

template <typename Column>
void Put(const std::vector<double>& from, Column* to) {
  to->Reserve(static_cast<int>(from.size()));
  for (double d : from) to->AddAlreadyReserved(static_cast<typename Column::value_type>(d));
}

template <typename Columns>
void PutColumns(const SampleBatch& b, const SampleFields& fields, Columns* c) {
  if (fields.uv) {
    Put(b.u, c->mutable_u());
    Put(b.v, c->mutable_v());
  }
  if (fields.xyz) {
    Put(b.x, c->mutable_x());
    Put(b.y, c->mutable_y());
    Put(b.z, c->mutable_z());
  }
  if (fields.normal) {
    Put(b.nx, c->mutable_nx());
    Put(b.ny, c->mutable_ny());
    Put(b.nz, c->mutable_nz());
  }
  if (fields.density) Put(b.density, c->mutable_density());
  if (fields.curve_position) Put(b.curve_position, c->mutable_curve_position());
}

#if defined(ABSL_IS_LITTLE_ENDIAN)
constexpr bool kLittleEndian = true;
#else
constexpr bool kLittleEndian = false;
#endif

// The IEEE 754 bits of `value` as T (double or float), little-endian, at `p`.
template <typename T>
void StoreLittleEndian(double value, char* p) {
  using Bits = std::conditional_t<sizeof(T) == 8, uint64_t, uint32_t>;
  const T t = static_cast<T>(value);
  Bits bits;
  std::memcpy(&bits, &t, sizeof bits);
  for (size_t b = 0; b < sizeof bits; ++b) p[b] = static_cast<char>(bits >> (8 * b));
}

// Values converted a block at a time through a buffer on the stack, so that
// the conversion runs in vector registers (a store through char* would make
// the compiler reload the column's bounds after every value).
constexpr size_t kConvertBlock = 1024;

template <typename T>
double LoadLittleEndian(const char* p) {
  using Bits = std::conditional_t<sizeof(T) == 8, uint64_t, uint32_t>;
  Bits bits = 0;
  for (size_t b = 0; b < sizeof bits; ++b)
    bits |= static_cast<Bits>(static_cast<unsigned char>(p[b])) << (8 * b);
  T t;
  std::memcpy(&t, &bits, sizeof t);
  return t;
}

// A raw column: the values of `from` as little-endian T, back to back.
template <typename T>
void PutRaw(const std::vector<double>& from, std::string* to) {
  to->resize(from.size() * sizeof(T));
  char* p = to->data();
  if (std::is_same_v<T, double> && kLittleEndian) {
    std::memcpy(p, from.data(), to->size());
    return;
  }
  if (kLittleEndian) {  // float32: convert, and store in host order
    const double* in = from.data();
    const size_t n = from.size();
    float block[kConvertBlock];
    for (size_t i = 0; i < n; i += kConvertBlock) {
      const size_t m = std::min(kConvertBlock, n - i);
      for (size_t j = 0; j < m; ++j) block[j] = static_cast<float>(in[i + j]);
      std::memcpy(p + i * sizeof(float), block, m * sizeof(float));
    }
    return;
  }
  for (size_t i = 0; i < from.size(); ++i) StoreLittleEndian<T>(from[i], p + i * sizeof(T));
}

template <typename T>
void PutRawColumns(const SampleBatch& b, const SampleFields& fields, v1::RawColumns* c) {
  if (fields.uv) {
    PutRaw<T>(b.u, c->mutable_u());
    PutRaw<T>(b.v, c->mutable_v());
  }
  if (fields.xyz) {
    PutRaw<T>(b.x, c->mutable_x());
    PutRaw<T>(b.y, c->mutable_y());
    PutRaw<T>(b.z, c->mutable_z());
  }
  if (fields.normal) {
    PutRaw<T>(b.nx, c->mutable_nx());
    PutRaw<T>(b.ny, c->mutable_ny());
    PutRaw<T>(b.nz, c->mutable_nz());
  }
  if (fields.density) PutRaw<T>(b.density, c->mutable_density());
  if (fields.curve_position) PutRaw<T>(b.curve_position, c->mutable_curve_position());
}

// Appends the n little-endian T values of `from` to `to`.
template <typename T>
absl::Status TakeRaw(const char* name, const std::string& from, size_t n, std::vector<double>* to) {
  if (from.size() != n * sizeof(T)) {
    return absl::DataLossError(
        absl::StrFormat("a batch's raw column %s has %d bytes for %d samples of %d bytes", name,
                        from.size(), n, sizeof(T)));
  }
  const size_t old = to->size();
  to->resize(old + n);
  double* q = to->data() + old;
  const char* p = from.data();
  if (std::is_same_v<T, double> && kLittleEndian) {
    std::memcpy(q, p, from.size());
  } else if (kLittleEndian) {
    for (size_t i = 0; i < n; ++i) {
      float f;
      std::memcpy(&f, p + i * sizeof(float), sizeof f);
      q[i] = f;
    }
  } else {
    for (size_t i = 0; i < n; ++i) q[i] = LoadLittleEndian<T>(p + i * sizeof(T));
  }
  return absl::OkStatus();
}

template <typename T>
absl::Status TakeRawColumns(const v1::RawColumns& c, const SampleFields& fields, size_t n,
                            SampleBatch* b) {
  if (fields.uv) {
    RETURN_IF_ERROR(TakeRaw<T>("u", c.u(), n, &b->u));
    RETURN_IF_ERROR(TakeRaw<T>("v", c.v(), n, &b->v));
  }
  if (fields.xyz) {
    RETURN_IF_ERROR(TakeRaw<T>("x", c.x(), n, &b->x));
    RETURN_IF_ERROR(TakeRaw<T>("y", c.y(), n, &b->y));
    RETURN_IF_ERROR(TakeRaw<T>("z", c.z(), n, &b->z));
  }
  if (fields.normal) {
    RETURN_IF_ERROR(TakeRaw<T>("nx", c.nx(), n, &b->nx));
    RETURN_IF_ERROR(TakeRaw<T>("ny", c.ny(), n, &b->ny));
    RETURN_IF_ERROR(TakeRaw<T>("nz", c.nz(), n, &b->nz));
  }
  if (fields.density) RETURN_IF_ERROR(TakeRaw<T>("density", c.density(), n, &b->density));
  if (fields.curve_position) {
    RETURN_IF_ERROR(TakeRaw<T>("curve_position", c.curve_position(), n, &b->curve_position));
  }
  return absl::OkStatus();
}

template <typename Column>
void PutIndexColumn(const std::vector<uint32_t>& from, Column* to) {
  to->Reserve(static_cast<int>(from.size()));
  for (uint32_t i : from) to->AddAlreadyReserved(i);
}

template <typename Column>
absl::Status TakeIndexColumn(const char* name, const Column& from, size_t n,
                             std::vector<uint32_t>* to) {
  if (static_cast<size_t>(from.size()) != n) {
    return absl::DataLossError(absl::StrFormat(
        "a batch's column %s has %d values for %d samples", name, from.size(), n));
  }
  to->insert(to->end(), from.begin(), from.end());
  return absl::OkStatus();
}

template <typename Column>
absl::Status Take(const char* name, const Column& from, size_t n, std::vector<double>* to) {
  if (static_cast<size_t>(from.size()) != n) {
    return absl::DataLossError(absl::StrFormat(
        "a batch's column %s has %d values for %d samples", name, from.size(), n));
  }
  to->insert(to->end(), from.begin(), from.end());
  return absl::OkStatus();
}

template <typename Columns>
absl::Status TakeColumns(const Columns& c, const SampleFields& fields, size_t n, SampleBatch* b) {
  if (fields.uv) {
    RETURN_IF_ERROR(Take("u", c.u(), n, &b->u));
    RETURN_IF_ERROR(Take("v", c.v(), n, &b->v));
  }
  if (fields.xyz) {
    RETURN_IF_ERROR(Take("x", c.x(), n, &b->x));
    RETURN_IF_ERROR(Take("y", c.y(), n, &b->y));
    RETURN_IF_ERROR(Take("z", c.z(), n, &b->z));
  }
  if (fields.normal) {
    RETURN_IF_ERROR(Take("nx", c.nx(), n, &b->nx));
    RETURN_IF_ERROR(Take("ny", c.ny(), n, &b->ny));
    RETURN_IF_ERROR(Take("nz", c.nz(), n, &b->nz));
  }
  if (fields.density) RETURN_IF_ERROR(Take("density", c.density(), n, &b->density));
  if (fields.curve_position) {
    RETURN_IF_ERROR(Take("curve_position", c.curve_position(), n, &b->curve_position));
  }
  return absl::OkStatus();
}

// Every column's length in a batch, to take back a partial append.
struct ColumnLengths {
  size_t index, face, triangle;
  std::array<size_t, 10> values;  // SampleBatch::ValueColumns()' order
};

ColumnLengths LengthsOf(const SampleBatch& b) {
  ColumnLengths l{b.index.size(), b.face.size(), b.triangle.size(), {}};
  for (size_t c = 0; c < l.values.size(); ++c)
    l.values[c] = (b.*SampleBatch::ValueColumns()[c]).size();
  return l;
}

// Shortens every column of `b` back to `l` (each is at least that long).
void ShortenTo(const ColumnLengths& l, SampleBatch* b) {
  b->index.resize(l.index), b->face.resize(l.face), b->triangle.resize(l.triangle);
  for (size_t c = 0; c < l.values.size(); ++c)
    (b->*SampleBatch::ValueColumns()[c]).resize(l.values[c]);
}

void ToProto(const TreeSummary::Cell& cell, v1::DepthCapWarning* out) {
  out->set_test(cell.test);
  out->set_u0(cell.u0), out->set_v0(cell.v0), out->set_size(cell.size);
  out->set_measured(cell.measured), out->set_limit(cell.limit);
}

std::vector<TreeSummary::Cell> FromProto(
    const google::protobuf::RepeatedPtrField<v1::DepthCapWarning>& cells) {
  std::vector<TreeSummary::Cell> out;
  out.reserve(cells.size());
  for (const v1::DepthCapWarning& w : cells) {
    out.push_back({w.test(), w.u0(), w.v0(), w.size(), w.measured(), w.limit()});
  }
  return out;
}

v1::Precision WirePrecision(ColumnPrecision precision) {
  return precision == ColumnPrecision::kFloat32 ? v1::PRECISION_FLOAT32 : v1::PRECISION_FLOAT64;
}

v1::ColumnEncoding WireEncoding(ColumnEncoding encoding) {
  return encoding == ColumnEncoding::kRaw ? v1::COLUMN_ENCODING_RAW : v1::COLUMN_ENCODING_PACKED;
}

}  // namespace

void ToProto(const TreeSummary& s, v1::TreeInfo* out) {
  out->set_kind(s.kind);
  out->set_key(s.key);
  out->set_key_with_grade(s.key_with_grade);
  out->set_canonical(s.canonical);
  out->set_grade(s.grade);
  out->set_cache_hit(s.cache_hit);
  out->set_refined(s.refined);
  out->set_leaves(s.leaves);
  out->set_bytes(s.bytes);
  out->set_min_depth(s.min_depth);
  out->set_max_depth(s.max_depth);
  out->set_tolerance(s.tolerance);
  out->set_flatness_capped_leaves(s.flatness_capped_leaves);
  out->set_mass_capped_leaves(s.mass_capped_leaves);
  for (const TreeSummary::Cell& cell : s.warnings) ToProto(cell, out->add_warnings());
  out->set_error_samples(s.error_samples);
  out->set_unresolved_error_samples(s.unresolved_error_samples);
  out->set_hidden_share(s.hidden_share);
  out->set_singular_leaves(s.singular_leaves);
  out->set_warped_leaves(s.warped_leaves);
  out->set_small_failing_leaves(s.small_failing_leaves);
  for (const TreeSummary::Cell& cell : s.singular) ToProto(cell, out->add_singular());
}

TreeSummary FromProto(const v1::TreeInfo& p) {
  TreeSummary s;
  s.kind = p.kind();
  s.key = p.key();
  s.key_with_grade = p.key_with_grade();
  s.canonical = p.canonical();
  s.grade = p.grade();
  s.cache_hit = p.cache_hit();
  s.refined = p.refined();
  s.leaves = p.leaves();
  s.bytes = p.bytes();
  s.min_depth = p.min_depth();
  s.max_depth = p.max_depth();
  s.tolerance = p.tolerance();
  s.flatness_capped_leaves = p.flatness_capped_leaves();
  s.mass_capped_leaves = p.mass_capped_leaves();
  s.warnings = FromProto(p.warnings());
  s.error_samples = p.error_samples();
  s.unresolved_error_samples = p.unresolved_error_samples();
  s.hidden_share = p.hidden_share();
  s.singular_leaves = p.singular_leaves();
  s.warped_leaves = p.warped_leaves();
  s.small_failing_leaves = p.small_failing_leaves();
  s.singular = FromProto(p.singular());
  return s;
}

StreamInfo FromProto(const v1::StreamHeader& p) {
  StreamInfo info;
  info.tree = FromProto(p.tree());
  info.algorithm_version = p.algorithm_version();
  info.seed = p.seed();
  info.begin = p.begin();
  info.end = p.end();
  info.expected_samples = p.expected_samples();
  return info;
}

absl::StatusOr<TreeSpec> FromProto(const v1::TreeSpec& p) {
  TreeSpec spec;
  if (!p.surface().empty()) spec.surface = p.surface();
  if (!p.density().empty()) spec.density = p.density();
  switch (p.curve()) {
    case v1::CURVE_HILBERT: spec.options.curve = CurveType::kHilbert; break;
    case v1::CURVE_HILBERT2: spec.options.curve = CurveType::kHilbert2; break;
    case v1::CURVE_PEANO: spec.options.curve = CurveType::kPeano; break;
    default: return absl::InvalidArgumentError(absl::StrFormat("unknown curve %d", p.curve()));
  }
  switch (p.estimator()) {
    case v1::AREA_ESTIMATOR_FFF:
      spec.options.estimator = AreaEstimator::kFirstFundamentalForm;
      break;
    case v1::AREA_ESTIMATOR_TRIANGLE: spec.options.estimator = AreaEstimator::kTriangle; break;
    case v1::AREA_ESTIMATOR_SQUARE: spec.options.estimator = AreaEstimator::kSquare; break;
    case v1::AREA_ESTIMATOR_QUADRATURE: spec.options.estimator = AreaEstimator::kQuadrature; break;
    default:
      return absl::InvalidArgumentError(
          absl::StrFormat("unknown area estimator %d", p.estimator()));
  }
  spec.options.tolerance = p.tolerance();
  spec.options.depth_cap = p.depth_cap();
  spec.options.rho = p.has_rho() ? p.rho() : 1.0;  // a 0 sent is the engine's to refuse
  return spec;
}

v1::TreeSpec ToProto(const TreeSpec& spec) {
  v1::TreeSpec p;
  p.set_surface(spec.surface);
  p.set_density(spec.density);
  switch (spec.options.curve) {
    case CurveType::kHilbert: p.set_curve(v1::CURVE_HILBERT); break;
    case CurveType::kHilbert2: p.set_curve(v1::CURVE_HILBERT2); break;
    case CurveType::kPeano: p.set_curve(v1::CURVE_PEANO); break;
  }
  switch (spec.options.estimator) {
    case AreaEstimator::kFirstFundamentalForm: p.set_estimator(v1::AREA_ESTIMATOR_FFF); break;
    case AreaEstimator::kTriangle: p.set_estimator(v1::AREA_ESTIMATOR_TRIANGLE); break;
    case AreaEstimator::kSquare: p.set_estimator(v1::AREA_ESTIMATOR_SQUARE); break;
    case AreaEstimator::kQuadrature: p.set_estimator(v1::AREA_ESTIMATOR_QUADRATURE); break;
  }
  p.set_tolerance(spec.options.tolerance);
  p.set_depth_cap(spec.options.depth_cap);
  p.set_rho(spec.options.rho);
  return p;
}

absl::StatusOr<SampleCall> FromProto(const v1::SampleRequest& p) {
  SampleCall call;
  SampleRequest& r = call.request;
  ASSIGN_OR_RETURN(r.tree, FromProto(p.tree()));
  switch (p.sequence()) {
    case v1::SEQUENCE_JITTERED: r.sequence = SequenceKind::kJittered; break;
    case v1::SEQUENCE_EQUAL: r.sequence = SequenceKind::kEqual; break;
    case v1::SEQUENCE_RANDOM: r.sequence = SequenceKind::kRandom; break;
    case v1::SEQUENCE_VAN_DER_CORPUT: r.sequence = SequenceKind::kVanDerCorput; break;
    case v1::SEQUENCE_PROGRESSIVE: r.sequence = SequenceKind::kProgressive; break;
    case v1::SEQUENCE_BLUE: r.sequence = SequenceKind::kBlue; break;
    case v1::SEQUENCE_SOBOL: r.sequence = SequenceKind::kSobol; break;
    default:
      return absl::InvalidArgumentError(absl::StrFormat("unknown sequence %d", p.sequence()));
  }
  StreamOptions& stream = call.stream;
  switch (p.precision()) {
    case v1::PRECISION_FLOAT64: stream.precision = ColumnPrecision::kFloat64; break;
    case v1::PRECISION_FLOAT32: stream.precision = ColumnPrecision::kFloat32; break;
    default:
      return absl::InvalidArgumentError(absl::StrFormat("unknown precision %d", p.precision()));
  }
  switch (p.column_encoding()) {
    case v1::COLUMN_ENCODING_PACKED: stream.encoding = ColumnEncoding::kPacked; break;
    case v1::COLUMN_ENCODING_RAW: stream.encoding = ColumnEncoding::kRaw; break;
    default:
      return absl::InvalidArgumentError(
          absl::StrFormat("unknown column encoding %d", p.column_encoding()));
  }
  stream.batch_size = p.batch_size();
  r.count = p.count();
  r.seed = p.seed();
  r.tree_count = p.tree_count();
  r.begin = p.begin();
  r.end = p.end();
  r.shard_index = p.shard_index();
  r.shard_count = p.shard_count();
  if (p.has_parameter_rect()) {
    const auto& q = p.parameter_rect();
    r.region = Region::ParameterRect(q.u0(), q.u1(), q.v0(), q.v1());
  } else if (p.has_box()) {
    const auto& b = p.box();
    r.region = Region::Box({b.min_x(), b.min_y(), b.min_z()}, {b.max_x(), b.max_y(), b.max_z()});
  }
  r.fields.normal = p.normals();
  r.fields.density = p.density();
  r.fields.curve_position = p.curve_position();
  r.fields.face = p.face();
  r.fields.triangle = p.triangle();
  r.fields.uv = !p.omit_uv();
  r.fields.xyz = !p.omit_xyz();
  if (WireValueColumns(r.fields) == 0) {
    return absl::InvalidArgumentError(
        "omit_uv and omit_xyz leave no value column: keep u v or x y z, or ask for normals, "
        "density "
        "or curve_position");
  }
  return call;
}

v1::SampleRequest ToProto(const SampleRequest& r, const StreamOptions& stream) {
  v1::SampleRequest p;
  *p.mutable_tree() = ToProto(r.tree);
  switch (r.sequence) {
    case SequenceKind::kJittered: p.set_sequence(v1::SEQUENCE_JITTERED); break;
    case SequenceKind::kEqual: p.set_sequence(v1::SEQUENCE_EQUAL); break;
    case SequenceKind::kRandom: p.set_sequence(v1::SEQUENCE_RANDOM); break;
    case SequenceKind::kVanDerCorput: p.set_sequence(v1::SEQUENCE_VAN_DER_CORPUT); break;
    case SequenceKind::kProgressive: p.set_sequence(v1::SEQUENCE_PROGRESSIVE); break;
    case SequenceKind::kBlue: p.set_sequence(v1::SEQUENCE_BLUE); break;
    case SequenceKind::kSobol: p.set_sequence(v1::SEQUENCE_SOBOL); break;
  }
  p.set_count(r.count);
  p.set_seed(r.seed);
  p.set_tree_count(r.tree_count);
  p.set_begin(r.begin);
  p.set_end(r.end);
  p.set_shard_index(r.shard_index);
  p.set_shard_count(r.shard_count);
  if (r.region.kind == Region::Kind::kParameterRect) {
    auto* q = p.mutable_parameter_rect();
    q->set_u0(r.region.u0), q->set_u1(r.region.u1), q->set_v0(r.region.v0), q->set_v1(r.region.v1);
  } else if (r.region.kind == Region::Kind::kBox) {
    auto* b = p.mutable_box();
    b->set_min_x(r.region.lo.x), b->set_min_y(r.region.lo.y), b->set_min_z(r.region.lo.z);
    b->set_max_x(r.region.hi.x), b->set_max_y(r.region.hi.y), b->set_max_z(r.region.hi.z);
  }
  p.set_normals(r.fields.normal);
  p.set_density(r.fields.density);
  p.set_curve_position(r.fields.curve_position);
  p.set_face(r.fields.face);
  p.set_triangle(r.fields.triangle);
  p.set_omit_uv(!r.fields.uv);
  p.set_omit_xyz(!r.fields.xyz);
  p.set_precision(WirePrecision(stream.precision));
  p.set_batch_size(stream.batch_size);
  p.set_column_encoding(WireEncoding(stream.encoding));
  return p;
}

void ToProto(const SampleBatch& b, const SampleFields& fields, const StreamOptions& stream,
             v1::SampleBatch* out) {
  const size_t n = b.size();
  out->set_size(static_cast<uint32_t>(n));
  // Whether the indices are consecutive, a block at a time (a test without an
  // early exit inside the block runs in vector registers).
  bool consecutive = true;
  const uint64_t* index = b.index.data();
  for (size_t i = 0; i < n && consecutive; i += kConvertBlock) {
    const size_t end = std::min(n, i + kConvertBlock);
    uint64_t differ = 0;
    for (size_t j = i; j < end; ++j) differ |= index[j] ^ (index[0] + j);
    consecutive = differ == 0;
  }
  out->set_first_index(n ? b.index[0] : 0);
  if (!consecutive) {
    out->mutable_index()->Reserve(static_cast<int>(n));
    for (uint64_t k : b.index) out->mutable_index()->AddAlreadyReserved(k);
  }
  const bool float32 = stream.precision == ColumnPrecision::kFloat32;
  if (stream.encoding == ColumnEncoding::kRaw) {
    v1::RawColumns* raw = out->mutable_raw();
    raw->set_precision(WirePrecision(stream.precision));
    if (float32) {
      PutRawColumns<float>(b, fields, raw);
    } else {
      PutRawColumns<double>(b, fields, raw);
    }
  } else if (float32) {
    PutColumns(b, fields, out->mutable_f32());
  } else {
    PutColumns(b, fields, out->mutable_f64());
  }
  if (fields.face) PutIndexColumn(b.face, out->mutable_face());
  if (fields.triangle) PutIndexColumn(b.triangle, out->mutable_triangle());
}

size_t WireValueColumns(const SampleFields& fields) {
  return (fields.uv ? 2 : 0) + (fields.xyz ? 3 : 0) + (fields.normal ? 3 : 0) +
         (fields.density ? 1 : 0) + (fields.curve_position ? 1 : 0);
}

uint32_t MaxSamplesPerMessage(const SampleFields& fields, ColumnPrecision precision,
                              bool indices_listed, size_t reserved_bytes,
                              size_t max_message_bytes) {
  const size_t columns = WireValueColumns(fields);
  const size_t width = precision == ColumnPrecision::kFloat32 ? sizeof(float) : sizeof(double);
  const size_t index_columns = (fields.face ? 1 : 0) + (fields.triangle ? 1 : 0);
  const size_t per_sample = columns * width + index_columns * sizeof(uint32_t) +
                            (indices_listed ? sizeof(uint64_t) : 0);
  // Each packed or raw column costs a tag and a length (at most 1 + 5
  // bytes); the batch's own fields, RawColumns.precision and the two message
  // wrappers at most 72 more.
  const size_t fixed = reserved_bytes + 6 * (columns + index_columns + 1) + 72;
  if (max_message_bytes <= fixed) return 0;
  return static_cast<uint32_t>(
      std::min<size_t>((max_message_bytes - fixed) / per_sample, UINT32_MAX));
}

absl::Status AppendFromProto(const v1::SampleBatch& in, const SampleFields& fields,
                             SampleBatch* out) {
  const size_t n = in.size();
  if (in.index_size() != 0 && static_cast<size_t>(in.index_size()) != n) {
    return absl::DataLossError(
        absl::StrFormat("a batch has %d indices for %d samples", in.index_size(), n));
  }
  if (n == 0) return absl::OkStatus();
  if (WireValueColumns(fields) == 0) {
    return absl::InvalidArgumentError("the request leaves no value column on the wire");
  }
  if (!in.has_f64() && !in.has_f32() && !in.has_raw())
    return absl::DataLossError("a batch has no columns");
  const bool raw32 = in.has_raw() && in.raw().precision() == v1::PRECISION_FLOAT32;
  if (in.has_raw() && !raw32 && in.raw().precision() != v1::PRECISION_FLOAT64) {
    return absl::DataLossError(absl::StrFormat("a batch's raw columns have unknown precision %d",
                                               in.raw().precision()));
  }
  // `size` is just a number on the wire; only the columns bound what it may
  // make us allocate. So the value columns come first (each is checked
  // before it is appended), the indices last; on an error everything
  // appended is taken back.
  const ColumnLengths before = LengthsOf(*out);
  absl::Status status;
  if (in.has_raw()) {
    status = raw32 ? TakeRawColumns<float>(in.raw(), fields, n, out)
                   : TakeRawColumns<double>(in.raw(), fields, n, out);
  } else {
    status = in.has_f64() ? TakeColumns(in.f64(), fields, n, out)
                          : TakeColumns(in.f32(), fields, n, out);
  }
  if (status.ok() && fields.face) status = TakeIndexColumn("face", in.face(), n, &out->face);
  if (status.ok() && fields.triangle)
    status = TakeIndexColumn("triangle", in.triangle(), n, &out->triangle);
  if (!status.ok()) {
    ShortenTo(before, out);
    return status;
  }
  if (in.index_size() == 0) {
    out->index.resize(before.index + n);
    for (size_t i = 0; i < n; ++i) out->index[before.index + i] = in.first_index() + i;
  } else {
    out->index.insert(out->index.end(), in.index().begin(), in.index().end());
  }
  return absl::OkStatus();
}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  // absl and gRPC share the canonical code numbering. The message travels in
  // a header (grpc-message): a long one would turn the real code into the
  // client's RESOURCE_EXHAUSTED about metadata size.
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()),
                      ClipMessage(status.message(), kMaxStatusMessageBytes));
}

absl::Status FromGrpcStatus(const grpc::Status& status) {
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

}  // namespace sfc
