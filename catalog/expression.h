// Compiled muparser expressions that many threads may evaluate at once.
//
// muparser keeps evaluation state inside each parser, so an Expression holds a
// pool of parsers, each compiled once, and lends one per evaluation.
// Thread-safety: Evaluate() is thread-safe.
#ifndef SFCSAMPLER_CATALOG_EXPRESSION_H_
#define SFCSAMPLER_CATALOG_EXPRESSION_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"

namespace sfc {

class Expression {
 public:
  // Compiles `text` over the named variables. `what` names the expression in
  // errors ("surface x"). Errors: INVALID_ARGUMENT with muparser's message and
  // the 0-based character position, e.g. for an unknown variable.
  static absl::StatusOr<std::unique_ptr<Expression>> Compile(std::string what, std::string text,
                                                             std::vector<std::string> variables);
  ~Expression();

  // Evaluates with variables[i] = values[i]. REQUIRES: values has one entry
  // per variable. Returns NaN if muparser fails at run time.
  double Evaluate(const double* values) const ABSL_LOCKS_EXCLUDED(mu_);

  const std::string& text() const { return text_; }

 private:
  struct Parser;
  Expression(std::string what, std::string text, std::vector<std::string> variables);
  absl::StatusOr<std::unique_ptr<Parser>> NewParser() const;

  // Constant after construction.
  const std::string what_;
  const std::string text_;
  const std::vector<std::string> variables_;

  mutable absl::Mutex mu_;
  mutable std::vector<std::unique_ptr<Parser>> idle_ ABSL_GUARDED_BY(mu_);
};

// Evaluates a constant expression such as "2*_pi" or "1/3". INVALID_ARGUMENT
// names `what` and the position of a syntax error.
absl::StatusOr<double> EvaluateConstant(const std::string& what, const std::string& text);

}  // namespace sfc

#endif  // SFCSAMPLER_CATALOG_EXPRESSION_H_
