// User expressions (muparser syntax) compiled once into an immutable flat
// program that evaluates over plain doubles, dual numbers (value, gradient and
// Hessian in (u, v): automatic differentiation) and rigorous intervals.
//
// muparser parses the text, reports syntax errors with their position and
// folds constants; its bytecode (reverse Polish notation) is then translated
// into our own instruction list. Evaluation needs no parser, no lock and no
// allocation: a small value stack lives on the caller's stack. Every
// construct the program cannot evaluate is rejected by Compile(), never at
// run time.
//
// Why our own evaluator rather than one of Debian's AD libraries: Trilinos
// Sacado's forward types differentiate C++ code written against them, so a
// run-time text would still need an interpreter of our own; ADOL-C can replay
// a recorded tape, but its tapes live in global state (not thread-safe, and
// replay allocates). Our interpreter, templated on the number type, also
// gives the interval instance that bounds patches (Surface::Bound), which
// neither provides, and keeps values bit-identical to the plain-double path.
// A flat program over a fixed set of operations is small, allocation-free and
// trivially thread-safe.
//
// Functions and operators (those muparser's default parser offers):
//   sin cos tan asin acos atan atan2 sinh cosh tanh asinh acosh atanh
//   log2 log10 log ln exp sqrt sign rint abs, min max sum avg (any number of
//   arguments), + - * / ^, unary - and +, < > <= >= == !=, && ||, c ? a : b,
//   constants _pi and _e (to full double precision).
//
// Thread-safety: an Expression is immutable after Compile(); every method is
// thread-safe.
#ifndef SFCSAMPLER_CATALOG_EXPRESSION_H_
#define SFCSAMPLER_CATALOG_EXPRESSION_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "catalog/dual.h"
#include "core/interval.h"

namespace sfc {

// sin and cos of the last few distinct arguments, so that the expressions of
// a surface point (x, y and z often share sin(pi u) or take both sin and cos
// of 2 pi v), or of a small grid of points, pay one sincos per argument, as
// the built-ins do. Results are bit-identical with or without it. Use one per
// point or grid and thread; it is a few hundred bytes on the stack.
class TrigCache {
 public:
  // sin(x) and cos(x) (SinCosOf), computed at most once per distinct x.
  void SinCos(double x, double* s, double* c);

 private:
  static constexpr int kSize = 8;
  int size_ = 0, next_ = 0;
  uint64_t bits_[kSize];
  double sin_[kSize], cos_[kSize];
};

class Expression {
 public:
  // Compiles `text` over the named variables. `what` names the expression in
  // errors ("surface expression x"). Errors: INVALID_ARGUMENT for an empty
  // text, a syntax error (muparser's message, which names the 0-based
  // character position once), an assignment, or several comma-separated
  // results.
  static absl::StatusOr<std::unique_ptr<Expression>> Compile(std::string what, std::string text,
                                                             std::vector<std::string> variables);
  ~Expression();
  Expression(const Expression&) = delete;
  Expression& operator=(const Expression&) = delete;

  // Evaluates with variables[i] = values[i]. REQUIRES: values has one entry
  // per variable. NaN where the expression is undefined (sqrt(-1), 0/0).
  double Evaluate(const double* values) const;
  // The same with dual numbers: the value is bit-identical to the double
  // evaluation; the derivatives are those of the inputs' seeds.
  Dual1 Evaluate(const Dual1* values) const;
  Dual2 Evaluate(const Dual2* values) const;
  // An interval enclosing Evaluate(x) for every double x_i in values[i], and
  // the exact real result (see core/interval.h).
  Interval Evaluate(const Interval* values) const;
  // The same, sharing sin and cos through `cache` with other evaluations at
  // the same point (which may change nothing but the time taken).
  double Evaluate(const double* values, TrigCache* cache) const;
  Dual1 Evaluate(const Dual1* values, TrigCache* cache) const;
  Dual2 Evaluate(const Dual2* values, TrigCache* cache) const;

  // Evaluate at n points, out[k] bit for bit Evaluate's value with
  // variables[i] = columns[i][k] (i < variables). Programs without
  // conditionals run an instruction at a time over chunks of points, sin and
  // cos as vector batches; the others point by point.
  void EvaluateMany(const double* const* columns, size_t variables, size_t n, double* out) const;

  const std::string& text() const { return text_; }
  // Whether the program reads variables[i] (after muparser's constant folding).
  bool Uses(size_t i) const;
  // Number of instructions of the compiled program (for tests and tracing).
  size_t program_size() const;

  struct Instruction;  // defined in expression.cc

 private:
  Expression(std::string text, std::vector<Instruction> code);

  const std::string text_;
  const std::vector<Instruction> code_;
  const bool straight_;  // no conditionals: EvaluateMany runs it over chunks
};

// Evaluates a constant expression such as "2*_pi" or "1/3" with the same
// functions and constants. INVALID_ARGUMENT names `what` and the position of
// a syntax error, or says the value is not finite.
absl::StatusOr<double> EvaluateConstant(const std::string& what, const std::string& text);

}  // namespace sfc

#endif  // SFCSAMPLER_CATALOG_EXPRESSION_H_
