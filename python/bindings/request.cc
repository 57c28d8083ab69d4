#include "python/bindings/request.h"

#include "absl/strings/str_format.h"
#include "catalog/catalog.h"
#include "core/curve.h"
#include "core/sequence.h"
#include "engine/sampling_engine.h"
#include "python/bindings/errors.h"
#include "python/bindings/register.h"
#include "request/index_range.h"
#include "request/model_files.h"
#include "request/model_spec.h"
#include "request/routing_key.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

// Accepts the shard as "i/K" (the CLI's form) or as a pair (i, K).
std::string ShardText(const py::object& shard) {
  if (shard.is_none()) return "";
  if (py::isinstance<py::str>(shard)) return shard.cast<std::string>();
  if (py::isinstance<py::tuple>(shard) || py::isinstance<py::list>(shard)) {
    auto seq = shard.cast<py::sequence>();
    if (seq.size() == 2) {
      return absl::StrFormat("%d/%d", seq[0].cast<uint64_t>(), seq[1].cast<uint64_t>());
    }
  }
  throw StatusException(
      absl::InvalidArgumentError("shard takes \"i/K\" or a pair (i, K) with 0 <= i < K"));
}

PyRequest MakeRequest(std::string surface, std::string density, std::string curve,
                      std::string estimator, double tolerance, int depth_cap, double rho,
                      uint64_t count, uint64_t seed, std::string sequence, uint64_t tree_count,
                      uint64_t begin, uint64_t end, const py::object& shard, std::string region,
                      bool normals, bool density_column, bool curve_position, bool face,
                      bool triangle) {
  PyRequest r;
  RequestFlags& f = r.flags;
  f.surface = std::move(surface);
  f.density = std::move(density);
  f.curve = std::move(curve);
  f.estimator = std::move(estimator);
  f.tolerance = tolerance;
  f.depth_cap = depth_cap;
  f.rho = rho;
  f.count = count;
  f.seed = seed;
  f.sequence = std::move(sequence);
  f.tree_count = tree_count;
  f.begin = begin;
  f.end = end;
  f.shard = ShardText(shard);
  f.region = std::move(region);
  f.normals = normals;
  f.density_column = density_column;
  f.curve_position = curve_position;
  f.face = face;
  f.triangle = triangle;
  auto parsed = ToSampleRequest(f);
  ThrowIfError(parsed.status());
  r.request = *std::move(parsed);
  return r;
}

}  // namespace

void RegisterRequest(py::module_& m) {
  // Defaults are the CLI's (request/request_flags.h).
  const RequestFlags d;
  py::class_<PyRequest>(m, "Request", R"doc(
A sampling request, parsed exactly as `sfcsampler sample` parses its flags
(each keyword is the flag without its leading dashes, '-' spelled '_').

surface, density: catalogue specs, e.g. "torus:R=2;r=0.5", "gaussian:floor=0.05".
curve: hilbert | hilbert2 | peano.  estimator: triangle | square | fff | quadrature.
tolerance: the paper's a (0 = 1% of the bounding-box diagonal).  depth_cap: the
paper's r (0 = deepest).  rho: max samples' worth of mass per leaf.
count: N, the size of the whole set.  seed: random seed.
sequence: jittered | equal | random | vandercorput | progressive | blue
(evenly spaced, biased for integration).
tree_count: size the tree for this many samples (0 = count).
begin, end: index range [begin, end) (end 0 = count); or shard "i/K" or (i, K).
region: "uv:U0,U1,V0,V1" or "box:X0,Y0,Z0,X1,Y1,Z1" (only samples inside).
normals, density_column, curve_position: the optional columns; face (CAD
models) and triangle (meshes: u, v are then barycentric) the model columns.
Raises sfcsampler.InvalidArgumentError for malformed values.)doc")
      .def(py::init(&MakeRequest), py::kw_only(), py::arg("surface") = d.surface,
           py::arg("density") = d.density, py::arg("curve") = d.curve,
           py::arg("estimator") = d.estimator, py::arg("tolerance") = d.tolerance,
           py::arg("depth_cap") = d.depth_cap, py::arg("rho") = d.rho, py::arg("count") = d.count,
           py::arg("seed") = d.seed, py::arg("sequence") = d.sequence,
           py::arg("tree_count") = d.tree_count, py::arg("begin") = d.begin, py::arg("end") = d.end,
           py::arg("shard") = py::none(), py::arg("region") = d.region,
           py::arg("normals") = d.normals, py::arg("density_column") = d.density_column,
           py::arg("curve_position") = d.curve_position, py::arg("face") = d.face,
           py::arg("triangle") = d.triangle)
      // The parsed request, field by field, for building the wire message.
      .def_property_readonly("surface", [](const PyRequest& r) { return r.request.tree.surface; })
      .def_property_readonly("density", [](const PyRequest& r) { return r.request.tree.density; })
      .def_property_readonly(
          "curve",
          [](const PyRequest& r) { return std::string(CurveName(r.request.tree.options.curve)); })
      .def_property_readonly(
          "estimator",
          [](const PyRequest& r) {
            return std::string(AreaEstimatorName(r.request.tree.options.estimator));
          })
      .def_property_readonly("tolerance",
                             [](const PyRequest& r) { return r.request.tree.options.tolerance; })
      .def_property_readonly("depth_cap",
                             [](const PyRequest& r) { return r.request.tree.options.depth_cap; })
      .def_property_readonly("rho", [](const PyRequest& r) { return r.request.tree.options.rho; })
      .def_property_readonly(
          "sequence",
          [](const PyRequest& r) { return std::string(SequenceName(r.request.sequence)); })
      .def_property_readonly("count", [](const PyRequest& r) { return r.request.count; })
      .def_property_readonly("seed", [](const PyRequest& r) { return r.request.seed; })
      .def_property_readonly("tree_count", [](const PyRequest& r) { return r.request.tree_count; })
      .def_property_readonly("begin", [](const PyRequest& r) { return r.request.begin; })
      .def_property_readonly("end", [](const PyRequest& r) { return r.request.end; })
      .def_property_readonly("shard_index",
                             [](const PyRequest& r) { return r.request.shard_index; })
      .def_property_readonly("shard_count",
                             [](const PyRequest& r) { return r.request.shard_count; })
      .def_property_readonly("region",
                             [](const PyRequest& r) -> py::object {
                               const Region& g = r.request.region;
                               switch (g.kind) {
                                 case Region::Kind::kAll:
                                   return py::none();
                                 case Region::Kind::kParameterRect:
                                   return py::make_tuple("uv", g.u0, g.u1, g.v0, g.v1);
                                 case Region::Kind::kBox:
                                   return py::make_tuple("box", g.lo.x, g.lo.y, g.lo.z, g.hi.x,
                                                         g.hi.y, g.hi.z);
                               }
                               return py::none();
                             })
      .def_property_readonly("normals", [](const PyRequest& r) { return r.request.fields.normal; })
      .def_property_readonly("density_column",
                             [](const PyRequest& r) { return r.request.fields.density; })
      .def_property_readonly("curve_position",
                             [](const PyRequest& r) { return r.request.fields.curve_position; })
      .def_property_readonly("face", [](const PyRequest& r) { return r.request.fields.face; })
      .def_property_readonly("triangle",
                             [](const PyRequest& r) { return r.request.fields.triangle; })
      .def_property_readonly(
          "surface_key", [](const PyRequest& r) { return RoutingKey(r.request.tree); },
          "the routing key sent as x-surface-key for consistent-hash proxies "
          "(request/routing_key.h)")
      .def_property_readonly(
          "monotone", [](const PyRequest& r) { return SequenceIsMonotone(r.request.sequence); },
          "whether indices grow along the stream (a broken stream resumes after the last index)")
      .def_property_readonly(
          "index_range",
          [](const PyRequest& r) {
            auto range = ResolveIndexRange(r.request);
            ThrowIfError(range.status());
            return py::make_tuple(range->first, range->second);
          },
          "the resolved index range (begin, end) before the region");
  m.def("upload_cut_hint", &UploadCutHint, py::arg("message"), py::arg("bytes"),
        "what to add to an upload's error when a proxy cut it (request/model_spec.h); '' if none");
  // The model files' facts of request/model_files.h, for python/sfcsampler/many.py.
  py::dict extensions;
  for (const ModelExtension& e : ModelExtensions()) {
    extensions[py::str(std::string(e.extension))] = py::str(std::string(ModelFormatName(e.format)));
  }
  m.attr("MODEL_EXTENSIONS") = extensions;
  m.attr("MODEL_PARSE_SECONDS") = kDefaultModelParseSeconds;
}

}  // namespace sfc::python
