#include "catalog/catalog.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <type_traits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "base/status_macros.h"
#include "catalog/expression.h"
#include "core/builtin_surfaces.h"

namespace sfc {
namespace {

const CatalogEntry* FindEntry(const std::vector<CatalogEntry>& entries, const std::string& name) {
  for (const CatalogEntry& e : entries) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

std::string Names(const std::vector<CatalogEntry>& entries) {
  std::vector<std::string> names;
  for (const CatalogEntry& e : entries) names.push_back(e.name);
  return absl::StrJoin(names, ", ");
}

// A spec split into its name and KEY=VALUE parameters, checked against the
// catalogue entry; missing parameters take their defaults.
struct Spec {
  const CatalogEntry* entry;
  std::map<std::string, std::string> values;
};

absl::StatusOr<Spec> ParseSpec(const std::string& kind, const std::vector<CatalogEntry>& catalog,
                               const std::string& text) {
  const std::string trimmed(absl::StripAsciiWhitespace(text));
  const size_t colon = trimmed.find(':');
  const std::string name = trimmed.substr(0, colon);
  const CatalogEntry* entry = FindEntry(catalog, name);
  if (entry == nullptr) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "unknown %s \"%s\"; known: %s (see `sfcsampler surfaces`)", kind, name, Names(catalog)));
  }
  Spec spec{entry, {}};
  if (colon != std::string::npos) {
    for (absl::string_view part :
         absl::StrSplit(trimmed.substr(colon + 1), ';', absl::SkipWhitespace())) {
      const size_t eq = part.find('=');
      const std::string key(absl::StripAsciiWhitespace(part.substr(0, eq)));
      bool known = false;
      for (const CatalogParameter& p : entry->parameters) known |= p.name == key;
      if (eq == absl::string_view::npos || !known) {
        std::vector<std::string> accepted;
        for (const CatalogParameter& p : entry->parameters) accepted.push_back(p.name);
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s \"%s\": \"%s\" is not a KEY=VALUE parameter it accepts; accepted: %s", kind, name,
            std::string(part), accepted.empty() ? "none" : absl::StrJoin(accepted, ", ")));
      }
      if (spec.values.count(key)) {
        return absl::InvalidArgumentError(
            absl::StrFormat("%s \"%s\": the parameter %s is given twice", kind, name, key));
      }
      spec.values[key] = std::string(absl::StripAsciiWhitespace(part.substr(eq + 1)));
    }
  }
  for (const CatalogParameter& p : entry->parameters) {
    if (spec.values.count(p.name)) continue;
    if (p.default_value.empty()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s \"%s\" needs the parameter %s (%s)", kind, name, p.name, p.meaning));
    }
    spec.values[p.name] = p.default_value;
  }
  return spec;
}

absl::StatusOr<double> Number(const Spec& spec, const std::string& key) {
  return EvaluateConstant(absl::StrCat(spec.entry->name, " parameter ", key), spec.values.at(key));
}

// name:key=value;... with numbers at full precision, in catalogue order.
std::string Canonical(const Spec& spec, const std::map<std::string, double>& numbers) {
  std::vector<std::string> parts;
  for (const CatalogParameter& p : spec.entry->parameters) {
    auto it = numbers.find(p.name);
    parts.push_back(it != numbers.end() ? absl::StrFormat("%s=%.17g", p.name, it->second)
                                        : absl::StrCat(p.name, "=", spec.values.at(p.name)));
  }
  return parts.empty() ? spec.entry->name
                       : absl::StrCat(spec.entry->name, ":", absl::StrJoin(parts, ";"));
}

absl::Status Positive(const std::string& what, double value) {
  if (value > 0) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrFormat("%s must be > 0, got %g", what, value));
}

// x(u,v), y(u,v), z(u,v) over the native box [u0,u1] x [v0,v1]. Point uses
// the plain-double program, Jet the dual-number one (exact derivatives, value
// bit-identical to Point), Bound the interval one.
class ExpressionSurface final : public Surface {
 public:
  ExpressionSurface(std::unique_ptr<Expression> x, std::unique_ptr<Expression> y,
                    std::unique_ptr<Expression> z, double u0, double u1, double v0, double v1)
      : x_(std::move(x)),
        y_(std::move(y)),
        z_(std::move(z)),
        u0_(u0),
        du_(u1 - u0),
        v0_(v0),
        dv_(v1 - v0) {}

  Vec3 Point(double u, double v) const override {
    const double uv[2] = {u0_ + u * du_, v0_ + v * dv_};
    TrigCache trig;
    return {x_->Evaluate(uv, &trig), y_->Evaluate(uv, &trig), z_->Evaluate(uv, &trig)};
  }

  // Point's values by the expressions' batch evaluation, chunk by chunk.
  void Points(const double* u, const double* v, size_t n, double* x, double* y,
              double* z) const override {
    constexpr size_t kChunk = 256;
    double nu[kChunk], nv[kChunk];
    const double* const columns[2] = {nu, nv};
    for (size_t at = 0; at < n; at += kChunk) {
      const size_t m = std::min(kChunk, n - at);
      for (size_t i = 0; i < m; ++i) nu[i] = u0_ + u[at + i] * du_, nv[i] = v0_ + v[at + i] * dv_;
      x_->EvaluateMany(columns, 2, m, x + at);
      y_->EvaluateMany(columns, 2, m, y + at);
      z_->EvaluateMany(columns, 2, m, z + at);
    }
  }

  SurfaceJet Jet(double u, double v, int order) const override {
    TrigCache trig;
    return order >= 2 ? JetOf<Dual2>(u, v, &trig) : JetOf<Dual1>(u, v, &trig);
  }

  // One TrigCache for the whole grid: sin and cos of an argument that
  // depends on u alone (or v alone) are computed once per row (or column),
  // as the built-ins' JetGrid does.
  void JetGrid(const double* us, int nu, const double* vs, int nv, int order,
               SurfaceJet* out) const override {
    TrigCache trig;
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        out[i * nv + j] =
            order >= 2 ? JetOf<Dual2>(us[i], vs[j], &trig) : JetOf<Dual1>(us[i], vs[j], &trig);
      }
    }
  }

  std::optional<Box3> Bound(double u0, double u1, double v0, double v1) const override {
    // The same operations as Point's u0_ + u * du_, on intervals.
    const Interval uv[2] = {
        Interval::Point(u0_) + Interval::Of(u0, u1) * Interval::Point(du_),
        Interval::Point(v0_) + Interval::Of(v0, v1) * Interval::Point(dv_)};
    return BoxOf(x_->Evaluate(uv), y_->Evaluate(uv), z_->Evaluate(uv));
  }

 private:
  // Derivatives with respect to the unit-square parameters: the native
  // parameters are u0_ + u du_ and v0_ + v dv_.
  template <typename D>
  SurfaceJet JetOf(double u, double v, TrigCache* trig) const {
    const D uv[2] = {D::Affine(u0_ + u * du_, du_, 0), D::Affine(v0_ + v * dv_, 0, dv_)};
    const D x = x_->Evaluate(uv, trig), y = y_->Evaluate(uv, trig), z = z_->Evaluate(uv, trig);
    SurfaceJet jet;
    jet.p = {x.v, y.v, z.v};
    jet.fu = {x.d[0], y.d[0], z.d[0]};
    jet.fv = {x.d[1], y.d[1], z.d[1]};
    if constexpr (std::is_same_v<D, Dual2>) {
      jet.fuu = {x.h[0], y.h[0], z.h[0]};
      jet.fuv = {x.h[1], y.h[1], z.h[1]};
      jet.fvv = {x.h[2], y.h[2], z.h[2]};
    }
    return jet;
  }

  const std::unique_ptr<Expression> x_, y_, z_;
  const double u0_, du_, v0_, dv_;
};

// delta(u, v, x, y, z) with (u, v) the unit-square parameters.
class ExpressionDensity final : public Density {
 public:
  explicit ExpressionDensity(std::unique_ptr<Expression> f)
      : f_(std::move(f)), uses_point_(f_->Uses(2) || f_->Uses(3) || f_->Uses(4)) {}
  double Value(const SurfacePoint& p) const override {
    const double values[5] = {p.u, p.v, p.p.x, p.p.y, p.p.z};
    return f_->Evaluate(values);
  }
  bool Bounds() const override { return true; }
  // The interval program over the rectangle and, where the expression reads
  // x, y or z, the surface's proven box of the patch (Surface::Bound; the
  // whole line where the surface cannot bound itself).
  double UpperBound(const Surface& surface, double u0, double u1, double v0,
                    double v1) const override {
    Interval values[5] = {Interval::Of(u0, u1), Interval::Of(v0, v1), Interval::NaN(),
                          Interval::NaN(), Interval::NaN()};
    if (uses_point_) {
      if (const std::optional<Box3> box = surface.Bound(u0, u1, v0, v1)) {
        values[2] = Interval::Of(box->lo.x, box->hi.x);
        values[3] = Interval::Of(box->lo.y, box->hi.y);
        values[4] = Interval::Of(box->lo.z, box->hi.z);
      }
    }
    const Interval r = f_->Evaluate(values);
    return r.maybe_nan || !(r.hi < INFINITY) ? INFINITY : r.hi;
  }

 private:
  const std::unique_ptr<Expression> f_;
  const bool uses_point_;  // reads x, y or z
};

}  // namespace

const std::vector<CatalogEntry>& SurfaceCatalog() {
  static const auto* const kEntries = new std::vector<CatalogEntry>{
      {"plane", "f(u,v) = (u, v, 0), (u,v) in [0,1]^2", "the unit square", {}},
      {"sphere",
       "f = r (sin a cos b, sin a sin b, cos a), a = pi u in [0,pi], b = 2 pi v in [0,2pi]",
       "sphere of radius r",
       {{"r", "1", "radius, > 0"}}},
      {"torus",
       "f = ((R + r cos b) cos a, (R + r cos b) sin a, r sin b), a, b in [0,2pi]",
       "torus of major radius R and tube radius r",
       {{"R", "1", "major radius, > 0"}, {"r", "0.4", "tube radius, > 0"}}},
      {"monkey_saddle", "f = (s, t, s^3 - 3 s t^2), (s,t) in [-1,1]^2", "the monkey saddle", {}},
      {"eight", "f = (cos a sin 2b, sin a sin 2b, sin b), a in [0,2pi], b in [-pi/2,pi/2]",
       "the eight surface", {}},
      {"whitney", "f = (s t, s, t^2), (s,t) in [-1,1]^2", "the Whitney umbrella", {}},
      {"superellipsoid",
       "f = (c(a)^e c(b)^e, c(a)^e s(b)^e, s(a)^e), signed powers, a in [-pi/2,pi/2], b in "
       "[-pi,pi]",
       "superellipsoid (paper Sect. 5.3); reparam=1 applies the power law "
       "angle = (pi/2) s^3/(s^3+(1-s)^3) on each quarter turn",
       {{"e", "1/3", "exponent, > 0"}, {"reparam", "0", "1 = power-law reparameterisation"}}},
      {"expr", "f = (x(u,v), y(u,v), z(u,v)), (u,v) in [u0,u1] x [v0,v1]",
       "user-defined by muparser expressions in u and v",
       {{"x", "", "expression in u, v"},
        {"y", "", "expression in u, v"},
        {"z", "", "expression in u, v"},
        {"u0", "0", "start of the u range"},
        {"u1", "1", "end of the u range, > u0"},
        {"v0", "0", "start of the v range"},
        {"v1", "1", "end of the v range, > v0"}}},
  };
  return *kEntries;
}

const std::vector<CatalogEntry>& DensityCatalog() {
  static const auto* const kEntries = new std::vector<CatalogEntry>{
      {"uniform", "delta = 1", "uniform with respect to surface area", {}},
      {"gaussian", "delta = max(|K|, floor)", "proportional to |Gaussian curvature|",
       {{"floor", "0", "lower bound, >= 0, keeps flat regions sampled"}}},
      {"mean", "delta = max(|H|, floor)", "proportional to |mean curvature|",
       {{"floor", "0", "lower bound, >= 0"}}},
      {"expr", "delta = f(u, v, x, y, z)",
       "user-defined muparser expression; (u,v) are unit-square parameters, (x,y,z) the point; "
       "written as expr:EXPRESSION",
       {}},
  };
  return *kEntries;
}

absl::StatusOr<SurfaceFromSpec> MakeSurface(const std::string& text) {
  ASSIGN_OR_RETURN(const Spec spec, ParseSpec("surface", SurfaceCatalog(), text));
  const std::string& name = spec.entry->name;
  std::map<std::string, double> numbers;
  for (const CatalogParameter& p : spec.entry->parameters) {
    if (name == "expr" && (p.name == "x" || p.name == "y" || p.name == "z")) continue;
    ASSIGN_OR_RETURN(numbers[p.name], Number(spec, p.name));
  }
  SurfaceFromSpec out;
  if (name == "plane") {
    out.surface = MakePlane();
  } else if (name == "sphere") {
    RETURN_IF_ERROR(Positive("sphere radius r", numbers["r"]));
    out.surface = MakeSphere(numbers["r"]);
  } else if (name == "torus") {
    RETURN_IF_ERROR(Positive("torus radius R", numbers["R"]));
    RETURN_IF_ERROR(Positive("torus radius r", numbers["r"]));
    out.surface = MakeTorus(numbers["R"], numbers["r"]);
  } else if (name == "monkey_saddle") {
    out.surface = MakeMonkeySaddle();
  } else if (name == "eight") {
    out.surface = MakeEightSurface();
  } else if (name == "whitney") {
    out.surface = MakeWhitneyUmbrella();
  } else if (name == "superellipsoid") {
    RETURN_IF_ERROR(Positive("superellipsoid exponent e", numbers["e"]));
    if (numbers["reparam"] != 0 && numbers["reparam"] != 1) {
      return absl::InvalidArgumentError("superellipsoid reparam must be 0 or 1");
    }
    out.surface = MakeSuperellipsoid(numbers["e"], numbers["reparam"] == 1);
  } else {  // expr
    if (!(numbers["u0"] < numbers["u1"]) || !(numbers["v0"] < numbers["v1"])) {
      return absl::InvalidArgumentError(
          absl::StrFormat("expr surface: the parameter box [%g,%g] x [%g,%g] is empty; it needs u0 "
                          "< u1 and v0 < v1",
                          numbers["u0"], numbers["u1"], numbers["v0"], numbers["v1"]));
    }
    std::unique_ptr<Expression> xyz[3];
    const char* axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      ASSIGN_OR_RETURN(xyz[i], Expression::Compile(absl::StrCat("surface expression ", axes[i]),
                                                   spec.values.at(axes[i]), {"u", "v"}));
    }
    out.surface = std::make_shared<ExpressionSurface>(std::move(xyz[0]), std::move(xyz[1]),
                                                      std::move(xyz[2]), numbers["u0"],
                                                      numbers["u1"], numbers["v0"], numbers["v1"]);
  }
  out.canonical = Canonical(spec, numbers);
  return out;
}

absl::StatusOr<DensityFromSpec> MakeDensity(const std::string& text) {
  const std::string trimmed(absl::StripAsciiWhitespace(text));
  DensityFromSpec out;
  if (absl::StartsWith(trimmed, "expr:")) {
    const std::string body(absl::StripAsciiWhitespace(trimmed.substr(5)));
    ASSIGN_OR_RETURN(auto f,
                     Expression::Compile("density expression", body, {"u", "v", "x", "y", "z"}));
    out.density = std::make_shared<ExpressionDensity>(std::move(f));
    out.canonical = absl::StrCat("expr:", body);
    out.name = "expr";
    return out;
  }
  ASSIGN_OR_RETURN(const Spec spec, ParseSpec("density", DensityCatalog(), trimmed));
  const std::string& name = spec.entry->name;
  if (name == "expr") {
    return absl::InvalidArgumentError(
        "density expr needs an expression: expr:EXPRESSION, e.g. expr:u+v");
  }
  std::map<std::string, double> numbers;
  for (const CatalogParameter& p : spec.entry->parameters) {
    ASSIGN_OR_RETURN(numbers[p.name], Number(spec, p.name));
  }
  if (name == "uniform") {
    out.density = MakeUniformDensity();
  } else {
    if (!(numbers["floor"] >= 0)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("density %s: floor must be >= 0, got %g", name, numbers["floor"]));
    }
    out.density = name == "gaussian" ? MakeGaussianCurvatureDensity(numbers["floor"])
                                     : MakeMeanCurvatureDensity(numbers["floor"]);
  }
  out.canonical = Canonical(spec, numbers);
  out.name = name;
  out.parameters = std::move(numbers);
  return out;
}

}  // namespace sfc
