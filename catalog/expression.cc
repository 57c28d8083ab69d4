#include "catalog/expression.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "muParser.h"

namespace sfc {

struct Expression::Parser {
  mu::Parser parser;
  std::vector<double> values;
};

namespace {

absl::Status ParserError(const std::string& what, const std::string& text,
                         const mu::Parser::exception_type& e) {
  if (e.GetPos() < 0) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: %s (in \"%s\")", what, e.GetMsg(), text));
  }
  return absl::InvalidArgumentError(absl::StrFormat(
      "%s: %s at position %d (token '%s') in \"%s\"", what, e.GetMsg(), e.GetPos(), e.GetToken(),
      text));
}

}  // namespace

Expression::Expression(std::string what, std::string text, std::vector<std::string> variables)
    : what_(std::move(what)), text_(std::move(text)), variables_(std::move(variables)) {}

Expression::~Expression() = default;

absl::StatusOr<std::unique_ptr<Expression::Parser>> Expression::NewParser() const {
  auto p = std::make_unique<Parser>();
  p->values.assign(variables_.size(), 0.5);
  try {
    for (size_t i = 0; i < variables_.size(); ++i) p->parser.DefineVar(variables_[i], &p->values[i]);
    p->parser.SetExpr(text_);
    p->parser.Eval();  // parses now, so syntax errors surface here
  } catch (const mu::Parser::exception_type& e) {
    return ParserError(what_, text_, e);
  }
  return p;
}

absl::StatusOr<std::unique_ptr<Expression>> Expression::Compile(std::string what, std::string text,
                                                                std::vector<std::string> variables) {
  auto expr =
      std::unique_ptr<Expression>(new Expression(std::move(what), std::move(text), std::move(variables)));
  auto parser = expr->NewParser();
  if (!parser.ok()) return parser.status();
  absl::MutexLock lock(&expr->mu_);
  expr->idle_.push_back(*std::move(parser));
  return expr;
}

double Expression::Evaluate(const double* values) const {
  std::unique_ptr<Parser> p;
  {
    absl::MutexLock lock(&mu_);
    if (!idle_.empty()) {
      p = std::move(idle_.back());
      idle_.pop_back();
    }
  }
  if (!p) {
    auto fresh = NewParser();  // compiled once before, so this cannot fail
    if (!fresh.ok()) return NAN;
    p = *std::move(fresh);
  }
  double result;
  try {
    for (size_t i = 0; i < p->values.size(); ++i) p->values[i] = values[i];
    result = p->parser.Eval();
  } catch (const mu::Parser::exception_type&) {
    result = NAN;
  }
  absl::MutexLock lock(&mu_);
  idle_.push_back(std::move(p));
  return result;
}

absl::StatusOr<double> EvaluateConstant(const std::string& what, const std::string& text) {
  try {
    mu::Parser parser;
    parser.SetExpr(text);
    const double value = parser.Eval();
    if (!std::isfinite(value)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s: \"%s\" is not a finite number", what, text));
    }
    return value;
  } catch (const mu::Parser::exception_type& e) {
    return ParserError(what, text, e);
  }
}

}  // namespace sfc
