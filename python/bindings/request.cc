#include "python/bindings/request.h"

#include "absl/strings/str_format.h"
#include "python/bindings/errors.h"
#include "python/bindings/register.h"
#include "request/model_files.h"
#include "request/model_spec.h"

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
(evenly spaced, biased for integration) | sobol (integration).
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
           py::arg("triangle") = d.triangle);
  // The model files' facts of request/model_files.h, for python/sfcsampler/many.py.
  py::dict extensions;
  for (const ModelExtension& e : ModelExtensions()) {
    extensions[py::str(std::string(e.extension))] = py::str(std::string(ModelFormatName(e.format)));
  }
  m.attr("MODEL_EXTENSIONS") = extensions;
  m.attr("MODEL_PARSE_SECONDS") = kDefaultModelParseSeconds;
}

}  // namespace sfc::python
