// User expressions: the compiled program reproduces muparser, its dual
// numbers give the built-ins' closed-form derivatives, its intervals enclose
// its values, and errors are reported once, at compile time.
#include "catalog/expression.h"

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "catalog/catalog.h"
#include "core/vector_math.h"
#include "gtest/gtest.h"
#include "muParser.h"

namespace sfc {
namespace {

std::unique_ptr<Expression> CompileUV(const std::string& text) {
  auto e = Expression::Compile("test", text, {"u", "v"});
  EXPECT_TRUE(e.ok()) << text << ": " << e.status();
  return e.ok() ? *std::move(e) : nullptr;
}

double Scale(const Vec3& a) { return std::max(1.0, Norm(a)); }

void ExpectClose(const Vec3& got, const Vec3& want, double rel, const std::string& what) {
  EXPECT_LE(Norm(got - want), rel * Scale(want))
      << what << ": got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x
      << ", " << want.y << ", " << want.z << ")";
}

// Each built-in written as an `expr:` surface over its native parameter box.
struct Pair {
  const char* builtin;
  const char* expr;
};
const Pair kPairs[] = {
    {"sphere", "expr:x=sin(u)*cos(v);y=sin(u)*sin(v);z=cos(u);u1=_pi;v1=2*_pi"},
    {"torus:R=1;r=0.4",
     "expr:x=(1+0.4*cos(v))*cos(u);y=(1+0.4*cos(v))*sin(u);z=0.4*sin(v);u1=2*_pi;v1=2*_pi"},
    {"monkey_saddle", "expr:x=u;y=v;z=u^3-3*u*v^2;u0=-1;u1=1;v0=-1;v1=1"},
    {"eight", "expr:x=cos(u)*sin(2*v);y=sin(u)*sin(2*v);z=sin(v);u1=2*_pi;v0=-_pi/2;v1=_pi/2"},
    {"whitney", "expr:x=u*v;y=u;z=v^2;u0=-1;u1=1;v0=-1;v1=1"},
};

// Automatic differentiation reproduces the closed forms to 1e-12 relative
// (per vector, relative to max(1, |reference|)), first and second order.
TEST(ExpressionSurface, DerivativesMatchTheBuiltInsClosedForms) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Pair& pair : kPairs) {
    auto builtin = MakeSurface(pair.builtin);
    auto expr = MakeSurface(pair.expr);
    ASSERT_TRUE(builtin.ok() && expr.ok()) << pair.expr;
    for (int i = 0; i < 2000; ++i) {
      const double u = i == 0 ? 0 : i == 1 ? 1 : unit(rng), v = i == 0 ? 0 : i == 1 ? 1 : unit(rng);
      const SurfaceJet want = builtin->surface->Jet(u, v, 2);
      const SurfaceJet got = expr->surface->Jet(u, v, 2);
      const std::string where = std::string(pair.builtin) + " at " + std::to_string(u) + "," +
                                std::to_string(v);
      ExpectClose(got.p, want.p, 1e-12, where + " p");
      ExpectClose(got.fu, want.fu, 1e-12, where + " fu");
      ExpectClose(got.fv, want.fv, 1e-12, where + " fv");
      ExpectClose(got.fuu, want.fuu, 1e-12, where + " fuu");
      ExpectClose(got.fuv, want.fuv, 1e-12, where + " fuv");
      ExpectClose(got.fvv, want.fvv, 1e-12, where + " fvv");
      // Order 1 gives the same first derivatives; Jet's point is Point's.
      const SurfaceJet first = expr->surface->Jet(u, v, 1);
      EXPECT_EQ(first.fu, got.fu);
      EXPECT_EQ(first.fv, got.fv);
      EXPECT_EQ(got.p, expr->surface->Point(u, v));
    }
  }
}

// JetGrid shares sin and cos over the grid and still equals Jet at each
// point, bit for bit.
TEST(ExpressionSurface, JetGridEqualsJetAtEachPoint) {
  for (const Pair& pair : kPairs) {
    auto expr = MakeSurface(pair.expr);
    ASSERT_TRUE(expr.ok());
    const double us[3] = {0.1, 0.35, 0.6}, vs[3] = {0.2, 0.45, 0.95};
    for (int order : {1, 2}) {
      SurfaceJet grid[9];
      expr->surface->JetGrid(us, 3, vs, 3, order, grid);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          const SurfaceJet one = expr->surface->Jet(us[i], vs[j], order);
          const SurfaceJet& g = grid[i * 3 + j];
          EXPECT_TRUE(g.p == one.p && g.fu == one.fu && g.fv == one.fv && g.fuu == one.fuu &&
                      g.fuv == one.fuv && g.fvv == one.fvv)
              << pair.expr;
        }
      }
    }
  }
}

// f(u, v) = 0 identically: its value, gradient and Hessian vanish, which
// checks the rules of different functions against each other.
TEST(Dual, IdentitiesHaveZeroDerivatives) {
  const char* kZero[] = {
      "sin(u)^2 + cos(u)^2 - 1",
      "sin(u*v)^2 + cos(u*v)^2 - 1",
      "tan(u*v) - sin(u*v)/cos(u*v)",
      "asin(sin(u*v)) - u*v",
      "acos(cos(u+v)) - (u+v)",
      "atan(tan(u-v)) - (u-v)",
      "atan2(sin(u+v), cos(u+v)) - (u+v)",
      "cosh(u*v)^2 - sinh(u*v)^2 - 1",
      "tanh(u+v) - sinh(u+v)/cosh(u+v)",
      "asinh(sinh(u*v)) - u*v",
      "acosh(cosh(u+v)) - (u+v)",
      "atanh(tanh(u*v)) - u*v",
      "exp(ln(u+v)) - (u+v)",
      "log(exp(u*v)) - u*v",
      "log2(u*v) - ln(u*v)/ln(2)",
      "log10(u+v) - log(u+v)/log(10)",
      "sqrt(u*v)^2 - u*v",
      "sqrt(u*v) - (u*v)^0.5",
      "u^v - exp(v*ln(u))",
      "2^(u*v) - exp(u*v*ln(2))",
      "(u*v)^3 - u^3*v^3",
      "(u+v)^4 - (u+v)*(u+v)*(u+v)*(u+v)",
      "1/(u+v) - (u+v)^(-1)",
      "(u*v)/(u+v) - 1/(1/u + 1/v)",
      "abs(u-v) - sign(u-v)*(u-v)",
      "min(u,v) + max(u,v) - (u+v)",
      "sum(u, v, u*v) - (u + v + u*v)",
      "avg(u, v, u*v) - (u + v + u*v)/3",
      "(u < v ? u*v : v*u) - u*v",
      "-u - (0 - u)",
      "+u*v - u*v",
      "rint(u) + rint(v) - rint(u) - rint(v)",
  };
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> dist(0.1, 0.7);
  for (const char* text : kZero) {
    auto e = CompileUV(text);
    ASSERT_NE(e, nullptr);
    for (int i = 0; i < 200; ++i) {
      const double u = dist(rng), v = dist(rng);
      const Dual2 in[2] = {Dual2::Affine(u, 1, 0), Dual2::Affine(v, 0, 1)};
      const Dual2 r = e->Evaluate(in);
      const double tol = 1e-12;
      EXPECT_NEAR(r.v, 0, tol) << text;
      EXPECT_NEAR(r.d[0], 0, tol) << text;
      EXPECT_NEAR(r.d[1], 0, tol) << text;
      EXPECT_NEAR(r.h[0], 0, 10 * tol) << text;
      EXPECT_NEAR(r.h[1], 0, 10 * tol) << text;
      EXPECT_NEAR(r.h[2], 0, 10 * tol) << text;
    }
  }
}

// Each function's dual rule against central differences of its double path
// (a check that the identities above are not all trivially zero).
TEST(Dual, EachFunctionMatchesFiniteDifferences) {
  const char* kFunctions[] = {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh",
                              "asinh", "acosh", "atanh", "log2", "log10", "log", "ln", "exp",
                              "sqrt", "abs"};
  for (const char* f : kFunctions) {
    // Arguments in each function's domain, away from kinks.
    const std::string arg = std::string(f) == "acosh" ? "(1.5 + u*v)" : "(0.2 + 0.5*u*v)";
    for (const std::string& text : {std::string(f) + arg, std::string(f) + arg + "^2 * v"}) {
      auto e = CompileUV(text);
      ASSERT_NE(e, nullptr);
      for (double u : {0.3, 0.55, 0.8}) {
        for (double v : {0.25, 0.6, 0.9}) {
          const Dual2 in[2] = {Dual2::Affine(u, 1, 0), Dual2::Affine(v, 0, 1)};
          const Dual2 r = e->Evaluate(in);
          auto at = [&](double a, double b) {
            const double x[2] = {a, b};
            return e->Evaluate(x);
          };
          const double h = 1e-4;
          const double fu = (at(u + h, v) - at(u - h, v)) / (2 * h);
          const double fv = (at(u, v + h) - at(u, v - h)) / (2 * h);
          const double fuu = (at(u + h, v) - 2 * at(u, v) + at(u - h, v)) / (h * h);
          const double fvv = (at(u, v + h) - 2 * at(u, v) + at(u, v - h)) / (h * h);
          const double fuv = (at(u + h, v + h) - at(u + h, v - h) - at(u - h, v + h) +
                              at(u - h, v - h)) / (4 * h * h);
          EXPECT_EQ(r.v, at(u, v)) << text;
          EXPECT_NEAR(r.d[0], fu, 1e-6 * std::max(1.0, std::fabs(fu))) << text;
          EXPECT_NEAR(r.d[1], fv, 1e-6 * std::max(1.0, std::fabs(fv))) << text;
          EXPECT_NEAR(r.h[0], fuu, 1e-4 * std::max(1.0, std::fabs(fuu))) << text;
          EXPECT_NEAR(r.h[1], fuv, 1e-4 * std::max(1.0, std::fabs(fuv))) << text;
          EXPECT_NEAR(r.h[2], fvv, 1e-4 * std::max(1.0, std::fabs(fvv))) << text;
        }
      }
    }
  }
}

// Everything a muparser user writes: every function, operator and branch.
const char* const kMuparserTexts[] = {
    "u", "-u", "+u", "2*u + 1", "1 - 3*u", "u*2/4", "u^2", "u^3", "u^4", "u^0", "u^1",
    "u^2.5", "u*u", "u+u", "(u+v)^2", "u/v", "u^v", "-u^2", "2^-u", "sin(u)", "cos(v)",
    "tan(u)", "asin(u)", "acos(v)", "atan(u)", "atan2(u, v)", "sinh(u)", "cosh(u)",
    "tanh(u)", "asinh(u)", "acosh(1+u)", "atanh(u/2)", "log2(u)", "log10(u)", "log(u)",
    "ln(v)", "exp(u)", "sqrt(v)", "sign(u-0.5)", "rint(3*u)", "abs(u-v)", "min(u, v, 0.3)",
    "max(u, v)", "sum(u, v, 1)", "avg(u, v)", "u < v", "u > v", "u <= v", "u >= v", "u == v",
    "u != v", "u < 0.5 && v > 0.5", "u < 0.5 || v > 0.5", "u < v ? u : v",
    "u < 0.3 ? 1 : u < 0.6 ? 2 : 3", "(u < v ? sin(u) : cos(v)) * 2", "_e^u", "2*_pi*u",
    "sin(_pi/4)", "1e-3*u", "min(u, v) * max(2, 3)", "-(-u)", "3 - -u", "u - -v*2",
};

// Everything a muparser user writes today still compiles and gives
// muparser's value (to rounding: our _pi is the full double pi, muparser's
// GCC build truncates it to 3.141592653589, and asinh/log2 are library calls).
TEST(Expression, AgreesWithMuparsersDefaultParser) {
  mu::Parser reference;
  double vars[2];
  reference.DefineVar("u", &vars[0]);
  reference.DefineVar("v", &vars[1]);
  for (const char* text : kMuparserTexts) {
    auto e = CompileUV(text);
    ASSERT_NE(e, nullptr) << text;
    reference.SetExpr(text);
    for (double u : {0.15, 0.4, 0.75}) {
      for (double v : {0.2, 0.4, 0.9}) {
        vars[0] = u, vars[1] = v;
        const double want = reference.Eval();
        const double got = e->Evaluate(vars);
        EXPECT_NEAR(got, want, 1e-11 * std::max(1.0, std::fabs(want))) << text << " at " << u
                                                                         << "," << v;
      }
    }
  }
}

// The batch evaluation gives Evaluate's bits for every text (straight-line
// programs by chunks, those with conditionals point by point), at batch
// lengths that leave every tail; and an expression surface's Points is its
// Point, bit for bit.
TEST(Expression, EvaluateManyIsEvaluateBitForBit) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-0.2, 1.2);
  std::vector<double> u(1000), v(1000);
  for (size_t k = 0; k < u.size(); ++k) u[k] = unit(rng), v[k] = unit(rng);
  u[0] = 0, v[0] = 0, u[1] = -0.0, v[1] = 0.5;
  const double* const columns[2] = {u.data(), v.data()};
  for (const char* text : kMuparserTexts) {
    auto e = CompileUV(text);
    ASSERT_NE(e, nullptr) << text;
    for (size_t n : {size_t{1}, size_t{7}, size_t{64}, size_t{65}, u.size()}) {
      std::vector<double> out(n);
      e->EvaluateMany(columns, 2, n, out.data());
      for (size_t k = 0; k < n; ++k) {
        const double p[2] = {u[k], v[k]};
        const double want = e->Evaluate(p);
        ASSERT_EQ(std::memcmp(&want, &out[k], sizeof want), 0) << text << " at " << u[k] << ","
                                                               << v[k];
      }
    }
  }
  for (const Pair& pair : kPairs) {
    auto surface = MakeSurface(pair.expr);
    ASSERT_TRUE(surface.ok());
    std::vector<double> su(u.size()), sv(u.size());
    for (size_t k = 0; k < u.size(); ++k)
      su[k] = std::fabs(u[k] - 0.2), sv[k] = std::fabs(v[k]) / 1.2;
    std::vector<double> x(u.size()), y(u.size()), z(u.size());
    surface->surface->Points(su.data(), sv.data(), su.size(), x.data(), y.data(), z.data());
    for (size_t k = 0; k < su.size(); ++k) {
      const Vec3 one = surface->surface->Point(su[k], sv[k]);
      const Vec3 got{x[k], y[k], z[k]};
      ASSERT_EQ(std::memcmp(&one, &got, sizeof one), 0) << pair.expr;
    }
  }
}

// muparser's messages name the position once; our additions do not repeat it.
TEST(Expression, ErrorsNameThePositionOnce) {
  const char* kBad[] = {"u+*v", "sin(u", "u)", "foo(u)", "w", "u v", "(u", "sin()", "1,",
                        "atan2(u)", "u ? 1", "u : 1"};
  for (const char* text : kBad) {
    auto e = Expression::Compile("surface expression x", text, {"u", "v"});
    ASSERT_FALSE(e.ok()) << text;
    EXPECT_EQ(e.status().code(), absl::StatusCode::kInvalidArgument);
    const std::string m(e.status().message());
    size_t count = 0;
    for (size_t p = m.find("position"); p != std::string::npos; p = m.find("position", p + 1)) {
      ++count;
    }
    EXPECT_LE(count, 1u) << m;
    EXPECT_NE(m.find("surface expression x"), std::string::npos) << m;
  }
  for (const char* empty : {"", "   "}) {
    auto e = Expression::Compile("surface expression z", empty, {"u", "v"});
    ASSERT_FALSE(e.ok());
    const std::string m(e.status().message());
    EXPECT_NE(m.find("empty"), std::string::npos) << m;
    EXPECT_EQ(m.find("position"), std::string::npos) << m;
  }
  auto bad = Expression::Compile("x", "u+*v", {"u", "v"});
  EXPECT_NE(std::string(bad.status().message()).find("position 2"), std::string::npos)
      << bad.status();
}

TEST(Expression, RejectsWhatItCannotEvaluateAtCompileTime) {
  for (const char* text : {"u = 1", "u, v", "u = v + 1, 2"}) {
    auto e = Expression::Compile("x", text, {"u", "v"});
    EXPECT_FALSE(e.ok()) << text;
    EXPECT_EQ(e.status().code(), absl::StatusCode::kInvalidArgument) << text;
  }
  // Deep nesting beyond the evaluation stack is refused with its reason.
  std::string deep = "u";
  for (int i = 0; i < 80; ++i) deep = "v+(" + deep + ")*u";
  auto d = Expression::Compile("x", deep, {"u", "v"});
  EXPECT_FALSE(d.ok());
  EXPECT_NE(std::string(d.status().message()).find("pending values"), std::string::npos)
      << d.status();
  std::string sum = "sum(";
  for (int i = 0; i < 100; ++i) sum += std::string(i ? "," : "") + "u*" + std::to_string(i + 1);
  sum += ")";
  auto s = Expression::Compile("x", sum, {"u", "v"});
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::string(s.status().message()).find("pending values"), std::string::npos)
      << s.status();
}

// Random points of a box map inside the interval evaluation, for expressions
// with every kind of operation, including undecided conditions.
TEST(Expression, IntervalsEncloseEveryPointValue) {
  const char* kTexts[] = {
      "sin(8*_pi*u) * cos(3*v)", "u^2 - v^3 + u^4", "(u - 0.5) * (u - 0.5)",
      "u < v ? u*u : sqrt(v)", "exp(u) / (1 + v)", "abs(u - v) + sign(u - 0.3)",
      "min(u, v, 0.5) + max(u*v, 0.2)", "atan2(v - 0.5, u + 0.1)", "tan(u) + asin(v - 0.5)",
      "log(u) + log2(v + 0.1)", "u^v", "(u - 0.5)^(-2)", "(u > 0.5 && v < 0.5) + (u == v)",
      "rint(5*u) + tanh(v) + cosh(u - v)", "acosh(1 + u) + atanh(v - 0.5) + asinh(u)",
      "sum(u, v, 1) / avg(u, 1)", "sqrt(u - 0.5)", "1 / (u - 0.5)", "-u^2", "u*2 + 1",
  };
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const char* text : kTexts) {
    auto e = CompileUV(text);
    ASSERT_NE(e, nullptr);
    for (int box = 0; box < 300; ++box) {
      const double w = std::pow(2.0, -unit(rng) * 12);
      const double u0 = unit(rng) * (1 - w), v0 = unit(rng) * (1 - w);
      const Interval in[2] = {Interval::Of(u0, u0 + w), Interval::Of(v0, v0 + w)};
      const Interval bound = e->Evaluate(in);
      for (int k = 0; k < 30; ++k) {
        const double x[2] = {k == 0 ? u0 : u0 + w * unit(rng),
                             k == 1 ? v0 + w : v0 + w * unit(rng)};
        const double value = e->Evaluate(x);
        if (std::isnan(value)) {
          EXPECT_TRUE(bound.maybe_nan) << text;
        } else {
          EXPECT_TRUE(bound.Contains(value))
              << text << " = " << value << " at " << x[0] << "," << x[1] << " outside ["
              << bound.lo << ", " << bound.hi << "]";
        }
      }
    }
  }
}

// Sharing sin and cos between the expressions of a point changes no bit.
TEST(Expression, TrigCacheChangesNothing) {
  auto x = CompileUV("sin(_pi*u)*cos(2*_pi*v)");
  auto y = CompileUV("sin(_pi*u)*sin(2*_pi*v) + cos(-u*0)");
  auto z = CompileUV("cos(_pi*u) + sin(u*0) - sin(-u*0) + sin(v)^2");
  for (double u : {0.0, 0.1, 0.5, 0.77}) {
    for (double v : {0.0, 0.3, 0.9}) {
      const double p[2] = {u, v};
      const Dual2 d[2] = {Dual2::Affine(u, 1, 0), Dual2::Affine(v, 0, 1)};
      TrigCache a, b;
      for (const Expression* e : {x.get(), y.get(), z.get()}) {
        const double plain = e->Evaluate(p);
        const double cached = e->Evaluate(p, &a);
        EXPECT_EQ(std::memcmp(&plain, &cached, sizeof plain), 0) << e->text();
        const Dual2 dp = e->Evaluate(d), dc = e->Evaluate(d, &b);
        EXPECT_EQ(std::memcmp(&dp, &dc, sizeof dp), 0) << e->text();
      }
    }
  }
}

TEST(Expression, ManyThreadsEvaluateOneExpression) {
  auto e = CompileUV("sin(u) * cos(v) + (u < v ? u : v)");
  ASSERT_NE(e, nullptr);
  std::vector<std::thread> threads;
  std::vector<int> wrong(4, 0);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20000; ++i) {
        const double u = (i % 97) / 97.0, v = (i % 89) / 89.0;
        const double x[2] = {u, v};
        // Our sin and cos are SLEEF's (core/vector_math.h), bit for bit.
        wrong[t] +=
            e->Evaluate(x) != math::SinCosOf(u).sin * math::SinCosOf(v).cos + (u < v ? u : v);
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int w : wrong) EXPECT_EQ(w, 0);
}

TEST(EvaluateConstant, UsesFullPrecisionPi) {
  auto pi = EvaluateConstant("c", "_pi");
  ASSERT_TRUE(pi.ok());
  EXPECT_EQ(*pi, 3.14159265358979323846);
  EXPECT_FALSE(EvaluateConstant("c", "1/0").ok());
  EXPECT_FALSE(EvaluateConstant("c", "u").ok());
}

}  // namespace
}  // namespace sfc
