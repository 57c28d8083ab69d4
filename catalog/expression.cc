#include "catalog/expression.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "core/vector_math.h"
#include "muParser.h"

namespace sfc {
namespace {

// The value stack of one evaluation lives on the caller's stack; Compile()
// rejects programs that need more.
constexpr int kMaxStack = 64;

constexpr double kPi = 3.14159265358979323846;
constexpr double kE = 2.71828182845904523536;

enum class Fn : uint8_t {
  kNone,
  kNeg,
  kSin,
  kCos,
  kTan,
  kAsin,
  kAcos,
  kAtan,
  kSinh,
  kCosh,
  kTanh,
  kAsinh,
  kAcosh,
  kAtanh,
  kLog2,
  kLog10,
  kLog,
  kExp,
  kSqrt,
  kSign,
  kRint,
  kAbs,
};

enum class Op : uint8_t {
  kConst,       // push a
  kVar,         // push x = vars[arg]
  kVarMulAdd,   // push x * a + b (muparser's cmVARMUL)
  kVarSquare,   // push x * x
  kVarCube,     // push (x * x) * x
  kVarFourth,   // push ((x * x) * x) * x
  kAdd,         // binary operators pop b, then a, and push a op b
  kSub,
  kMul,
  kDiv,
  kPow,
  kLess,
  kGreater,
  kLessEqual,
  kGreaterEqual,
  kEqual,
  kNotEqual,
  kAnd,
  kOr,
  kFunc,   // top = fn(top)
  kAtan2,  // pop x, then y; push atan2(y, x)
  kSum,    // pop arg values, push their sum (muparser's order)
  kAvg,
  kMin,
  kMax,
  kIf,     // pop the condition; when false continue after the kElse at arg
  kElse,   // end of the taken then-branch: continue after the kEndIf at arg
  kEndIf,  // end of an else-branch
};

// The functions we define in muparser. The callback's user-data pointer
// points into this table, which is how a cmFUNC token is recognised.
struct Builtin {
  const char* name;
  Op op;
  Fn fn;
  int arity;  // -1: any number >= 1
};

constexpr Builtin kBuiltins[] = {
    {"sin", Op::kFunc, Fn::kSin, 1},       {"cos", Op::kFunc, Fn::kCos, 1},
    {"tan", Op::kFunc, Fn::kTan, 1},       {"asin", Op::kFunc, Fn::kAsin, 1},
    {"acos", Op::kFunc, Fn::kAcos, 1},     {"atan", Op::kFunc, Fn::kAtan, 1},
    {"atan2", Op::kAtan2, Fn::kNone, 2},   {"sinh", Op::kFunc, Fn::kSinh, 1},
    {"cosh", Op::kFunc, Fn::kCosh, 1},     {"tanh", Op::kFunc, Fn::kTanh, 1},
    {"asinh", Op::kFunc, Fn::kAsinh, 1},   {"acosh", Op::kFunc, Fn::kAcosh, 1},
    {"atanh", Op::kFunc, Fn::kAtanh, 1},   {"log2", Op::kFunc, Fn::kLog2, 1},
    {"log10", Op::kFunc, Fn::kLog10, 1},   {"log", Op::kFunc, Fn::kLog, 1},
    {"ln", Op::kFunc, Fn::kLog, 1},        {"exp", Op::kFunc, Fn::kExp, 1},
    {"sqrt", Op::kFunc, Fn::kSqrt, 1},     {"sign", Op::kFunc, Fn::kSign, 1},
    {"rint", Op::kFunc, Fn::kRint, 1},     {"abs", Op::kFunc, Fn::kAbs, 1},
    {"sum", Op::kSum, Fn::kNone, -1},      {"avg", Op::kAvg, Fn::kNone, -1},
    {"min", Op::kMin, Fn::kNone, -1},      {"max", Op::kMax, Fn::kNone, -1},
};

// ---- Plain-double semantics; the dual numbers' values use the same calls.

double Sin(double x) {
  double s, c;
  SinCosOf(x, &s, &c);
  return s;
}
double Cos(double x) {
  double s, c;
  SinCosOf(x, &s, &c);
  return c;
}
double Tan(double x) { return math::Tan(x); }
double Asin(double x) { return math::Asin(x); }
double Acos(double x) { return math::Acos(x); }
double Atan(double x) { return math::Atan(x); }
double Atan2(double y, double x) { return math::Atan2(y, x); }
double Sinh(double x) { return math::Sinh(x); }
double Cosh(double x) { return math::Cosh(x); }
double Tanh(double x) { return math::Tanh(x); }
double Asinh(double x) { return math::Asinh(x); }
double Acosh(double x) { return math::Acosh(x); }
double Atanh(double x) { return math::Atanh(x); }
double Log2(double x) { return math::Log2(x); }
double Log10(double x) { return math::Log10(x); }
double Log(double x) { return math::Log(x); }
double Exp(double x) { return math::Exp(x); }
double Sqrt(double x) { return std::sqrt(x); }
double Sign(double x) { return SignOf(x); }
double Rint(double x) { return RintOf(x); }
double Abs(double x) { return AbsOf(x); }
double Pow(double a, double b) { return math::Pow(a, b); }
double Min(double a, double b) { return MinOf(a, b); }
double Max(double a, double b) { return MaxOf(a, b); }

// ---- What differs between the number types: constants, conditions and
// comparisons, and the muparser fused opcodes.

template <typename T>
T Constant(double c);
template <>
double Constant<double>(double c) {
  return c;
}
template <>
Dual1 Constant<Dual1>(double c) {
  return Dual1::Constant(c);
}
template <>
Dual2 Constant<Dual2>(double c) {
  return Dual2::Constant(c);
}
template <>
Interval Constant<Interval>(double c) {
  return Interval::Point(c);
}

// muparser takes the then-branch unless the condition == 0 (NaN is true).
Truth Condition(double x) { return x == 0 ? Truth::kFalse : Truth::kTrue; }
template <int N>
Truth Condition(const Dual<N>& x) {
  return Condition(x.v);
}
Truth Condition(const Interval& x) { return TruthOf(x); }

double Lt(double a, double b) { return a < b; }
double Le(double a, double b) { return a <= b; }
double Eq(double a, double b) { return a == b; }
double Ne(double a, double b) { return a != b; }
double And(double a, double b) { return a && b; }
double Or(double a, double b) { return a || b; }
template <int N>
Dual<N> Lt(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v < b.v);
}
template <int N>
Dual<N> Le(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v <= b.v);
}
template <int N>
Dual<N> Eq(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v == b.v);
}
template <int N>
Dual<N> Ne(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v != b.v);
}
template <int N>
Dual<N> And(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v && b.v);
}
template <int N>
Dual<N> Or(const Dual<N>& a, const Dual<N>& b) {
  return Dual<N>::Constant(a.v || b.v);
}
Interval Lt(const Interval& a, const Interval& b) { return Less(a, b); }
Interval Le(const Interval& a, const Interval& b) { return LessEqual(a, b); }
Interval Eq(const Interval& a, const Interval& b) { return Equal(a, b); }
Interval Ne(const Interval& a, const Interval& b) { return NotEqual(a, b); }
Interval And(const Interval& a, const Interval& b) { return LogicalAnd(a, b); }
Interval Or(const Interval& a, const Interval& b) { return LogicalOr(a, b); }

double VarMulAdd(double x, double a, double b) { return x * a + b; }
template <int N>
Dual<N> VarMulAdd(const Dual<N>& x, double a, double b) {
  return MulAdd(x, a, b);
}
Interval VarMulAdd(const Interval& x, double a, double b) {
  return x * Interval::Point(a) + Interval::Point(b);
}

// x*x, (x*x)*x, ((x*x)*x)*x; intervals use the dependency-aware forms.
template <typename T>
T VarSquare(const T& x) {
  return x * x;
}
template <typename T>
T VarCube(const T& x) {
  return (x * x) * x;
}
template <typename T>
T VarFourth(const T& x) {
  return ((x * x) * x) * x;
}
Interval VarSquare(const Interval& x) { return Square(x); }
Interval VarCube(const Interval& x) { return Cube(x); }
Interval VarFourth(const Interval& x) { return Fourth(x); }

// sin or cos of x from s = sin(x) and c = cos(x) (the cached path).
double TrigFrom(bool sine, double, double s, double c) { return sine ? s : c; }
template <int N>
Dual<N> TrigFrom(bool sine, const Dual<N>& x, double s, double c) {
  return sine ? SinFrom(x, s, c) : CosFrom(x, s, c);
}
double ValueOf(double x) { return x; }
template <int N>
double ValueOf(const Dual<N>& x) {
  return x.v;
}

// Hull of the two branches of an undecided condition; only intervals have
// undecided conditions.
double Union(double a, double) { return a; }
template <int N>
Dual<N> Union(const Dual<N>& a, const Dual<N>&) {
  return a;
}
Interval Union(const Interval& a, const Interval& b) { return Hull(a, b); }

template <typename T>
T Apply(Fn fn, const T& x) {
  switch (fn) {
    case Fn::kNeg:
      return -x;
    case Fn::kSin:
      return Sin(x);
    case Fn::kCos:
      return Cos(x);
    case Fn::kTan:
      return Tan(x);
    case Fn::kAsin:
      return Asin(x);
    case Fn::kAcos:
      return Acos(x);
    case Fn::kAtan:
      return Atan(x);
    case Fn::kSinh:
      return Sinh(x);
    case Fn::kCosh:
      return Cosh(x);
    case Fn::kTanh:
      return Tanh(x);
    case Fn::kAsinh:
      return Asinh(x);
    case Fn::kAcosh:
      return Acosh(x);
    case Fn::kAtanh:
      return Atanh(x);
    case Fn::kLog2:
      return Log2(x);
    case Fn::kLog10:
      return Log10(x);
    case Fn::kLog:
      return Log(x);
    case Fn::kExp:
      return Exp(x);
    case Fn::kSqrt:
      return Sqrt(x);
    case Fn::kSign:
      return Sign(x);
    case Fn::kRint:
      return Rint(x);
    case Fn::kAbs:
      return Abs(x);
    case Fn::kNone:
      break;
  }
  return x;  // unreachable: Compile() admits only the functions above
}

// sum, avg, min, max over args[0..n), in muparser's order of operations.
template <typename T>
T ApplyMulti(Op op, const T* args, int n) {
  T r;
  switch (op) {
    case Op::kSum:
    case Op::kAvg:
      r = Constant<T>(0);
      for (int i = 0; i < n; ++i) r = r + args[i];
      return op == Op::kAvg ? r / Constant<T>(n) : r;
    case Op::kMin:
      r = args[0];
      for (int i = 0; i < n; ++i) r = Min(r, args[i]);
      return r;
    default:  // kMax
      r = args[0];
      for (int i = 0; i < n; ++i) r = Max(r, args[i]);
      return r;
  }
}

}  // namespace

struct Expression::Instruction {
  Op op;
  Fn fn;
  int32_t arg;  // variable index, argument count or jump target
  double a, b;  // constants
};

namespace {

using Instruction = Expression::Instruction;

// Runs code[begin, end) on the stack st (top at sp). An undecided condition
// (intervals only) runs both branches and keeps the hull of their results.
template <typename T>
void Execute(const Instruction* code, int begin, int end, T* st, int& sp, const T* vars,
             TrigCache* cache) {
  for (int pc = begin; pc < end; ++pc) {
    const Instruction& in = code[pc];
    switch (in.op) {
      case Op::kConst:
        st[++sp] = Constant<T>(in.a);
        break;
      case Op::kVar:
        st[++sp] = vars[in.arg];
        break;
      case Op::kVarMulAdd:
        st[++sp] = VarMulAdd(vars[in.arg], in.a, in.b);
        break;
      case Op::kVarSquare:
        st[++sp] = VarSquare(vars[in.arg]);
        break;
      case Op::kVarCube:
        st[++sp] = VarCube(vars[in.arg]);
        break;
      case Op::kVarFourth:
        st[++sp] = VarFourth(vars[in.arg]);
        break;
      case Op::kAdd:
        --sp, st[sp] = st[sp] + st[sp + 1];
        break;
      case Op::kSub:
        --sp, st[sp] = st[sp] - st[sp + 1];
        break;
      case Op::kMul:
        --sp, st[sp] = st[sp] * st[sp + 1];
        break;
      case Op::kDiv:
        --sp, st[sp] = st[sp] / st[sp + 1];
        break;
      case Op::kPow:
        --sp, st[sp] = Pow(st[sp], st[sp + 1]);
        break;
      case Op::kLess:
        --sp, st[sp] = Lt(st[sp], st[sp + 1]);
        break;
      case Op::kGreater:
        --sp, st[sp] = Lt(st[sp + 1], st[sp]);
        break;
      case Op::kLessEqual:
        --sp, st[sp] = Le(st[sp], st[sp + 1]);
        break;
      case Op::kGreaterEqual:
        --sp, st[sp] = Le(st[sp + 1], st[sp]);
        break;
      case Op::kEqual:
        --sp, st[sp] = Eq(st[sp], st[sp + 1]);
        break;
      case Op::kNotEqual:
        --sp, st[sp] = Ne(st[sp], st[sp + 1]);
        break;
      case Op::kAnd:
        --sp, st[sp] = And(st[sp], st[sp + 1]);
        break;
      case Op::kOr:
        --sp, st[sp] = Or(st[sp], st[sp + 1]);
        break;
      case Op::kFunc:
        if constexpr (!std::is_same_v<T, Interval>) {
          if (cache != nullptr && (in.fn == Fn::kSin || in.fn == Fn::kCos)) {
            double s, c;
            cache->SinCos(ValueOf(st[sp]), &s, &c);
            st[sp] = TrigFrom(in.fn == Fn::kSin, st[sp], s, c);
            break;
          }
        }
        st[sp] = Apply(in.fn, st[sp]);
        break;
      case Op::kAtan2:
        --sp, st[sp] = Atan2(st[sp], st[sp + 1]);
        break;
      case Op::kSum:
      case Op::kAvg:
      case Op::kMin:
      case Op::kMax:
        sp -= in.arg - 1;
        st[sp] = ApplyMulti(in.op, &st[sp], in.arg);
        break;
      case Op::kIf: {
        const Truth t = Condition(st[sp--]);
        if (t == Truth::kFalse) {
          pc = in.arg;  // the kElse; the loop steps into the else-branch
        } else if (t == Truth::kUnknown) {
          const int else_pc = in.arg, endif_pc = code[else_pc].arg;
          Execute(code, pc + 1, else_pc, st, sp, vars, cache);
          const T then_value = st[sp--];
          Execute(code, else_pc + 1, endif_pc, st, sp, vars, cache);
          st[sp] = Union(then_value, st[sp]);
          pc = endif_pc;
        }
        break;
      }
      case Op::kElse:
        pc = in.arg;  // skip the else-branch
        break;
      case Op::kEndIf:
        break;
    }
  }
}

template <typename T>
T Run(const std::vector<Instruction>& code, const T* vars, TrigCache* cache = nullptr) {
  T st[kMaxStack];
  int sp = -1;
  Execute(code.data(), 0, static_cast<int>(code.size()), st, sp, vars, cache);
  return st[0];
}

// Points evaluated at once by ExecuteMany.
constexpr size_t kBatch = 64;

// Runs a program without conditionals over m <= kBatch points at once: stack
// entry k is the column st[k][0..m), and each instruction runs over its
// columns with Execute<double>'s operations in the same order (the same
// bits), sin and cos in one vector batch (math::SinCosOf, SinCosOf's bits).
void ExecuteMany(const std::vector<Instruction>& code, const double* const* vars, size_t m,
                 double (*st)[kBatch]) {
  int sp = -1;
  double s[kBatch], c[kBatch], args[kMaxStack];
  for (const Instruction& in : code) {
    double* top = st[sp + 1];  // a pushed column
    double* a = sp >= 1 ? st[sp - 1] : nullptr;  // a binary operator's columns
    const double* b = sp >= 0 ? st[sp] : nullptr;
    // A binary operator: a[i] = f(a[i], b[i]), then one column fewer.
    const auto binary = [&](auto f) {
      for (size_t i = 0; i < m; ++i) a[i] = f(a[i], b[i]);
      --sp;
    };
    switch (in.op) {
      case Op::kConst:
        std::fill(top, top + m, in.a), ++sp;
        break;
      case Op::kVar:
        std::copy(vars[in.arg], vars[in.arg] + m, top), ++sp;
        break;
      case Op::kVarMulAdd:
        for (size_t i = 0; i < m; ++i) top[i] = VarMulAdd(vars[in.arg][i], in.a, in.b);
        ++sp;
        break;
      case Op::kVarSquare:
        for (size_t i = 0; i < m; ++i) top[i] = VarSquare(vars[in.arg][i]);
        ++sp;
        break;
      case Op::kVarCube:
        for (size_t i = 0; i < m; ++i) top[i] = VarCube(vars[in.arg][i]);
        ++sp;
        break;
      case Op::kVarFourth:
        for (size_t i = 0; i < m; ++i) top[i] = VarFourth(vars[in.arg][i]);
        ++sp;
        break;
      case Op::kAdd:
        binary([](double x, double y) { return x + y; });
        break;
      case Op::kSub:
        binary([](double x, double y) { return x - y; });
        break;
      case Op::kMul:
        binary([](double x, double y) { return x * y; });
        break;
      case Op::kDiv:
        binary([](double x, double y) { return x / y; });
        break;
      case Op::kPow:
        binary([](double x, double y) { return Pow(x, y); });
        break;
      case Op::kLess:
        binary([](double x, double y) { return Lt(x, y); });
        break;
      case Op::kGreater:
        binary([](double x, double y) { return Lt(y, x); });
        break;
      case Op::kLessEqual:
        binary([](double x, double y) { return Le(x, y); });
        break;
      case Op::kGreaterEqual:
        binary([](double x, double y) { return Le(y, x); });
        break;
      case Op::kEqual:
        binary([](double x, double y) { return Eq(x, y); });
        break;
      case Op::kNotEqual:
        binary([](double x, double y) { return Ne(x, y); });
        break;
      case Op::kAnd:
        binary([](double x, double y) { return And(x, y); });
        break;
      case Op::kOr:
        binary([](double x, double y) { return Or(x, y); });
        break;
      case Op::kFunc:
        if (in.fn == Fn::kSin || in.fn == Fn::kCos) {
          math::SinCosOf(st[sp], m, s, c);
          std::copy_n(in.fn == Fn::kSin ? s : c, m, st[sp]);
        } else {
          for (size_t i = 0; i < m; ++i) st[sp][i] = Apply(in.fn, st[sp][i]);
        }
        break;
      case Op::kAtan2:
        for (size_t i = 0; i < m; ++i) a[i] = Atan2(a[i], b[i]);
        --sp;
        break;
      case Op::kSum:
      case Op::kAvg:
      case Op::kMin:
      case Op::kMax:
        sp -= in.arg - 1;
        for (size_t i = 0; i < m; ++i) {
          for (int k = 0; k < in.arg; ++k) args[k] = st[sp + k][i];
          st[sp][i] = ApplyMulti(in.op, args, in.arg);
        }
        break;
      case Op::kIf:
      case Op::kElse:
      case Op::kEndIf:
        break;  // not reached: programs with conditionals run point by point
    }
  }
}

bool HasConditionals(const std::vector<Instruction>& code) {
  return std::any_of(code.begin(), code.end(), [](const Instruction& in) {
    return in.op == Op::kIf || in.op == Op::kElse || in.op == Op::kEndIf;
  });
}

// ---- muparser callbacks: used by muparser only to parse and to fold
// constants, so they compute exactly what Run<double> computes.

double CallUnary(void* data, double x) { return Apply(static_cast<const Builtin*>(data)->fn, x); }
double CallAtan2(void*, double y, double x) { return Atan2(y, x); }
double CallMulti(void* data, const double* args, int n) {
  return ApplyMulti(static_cast<const Builtin*>(data)->op, args, n);
}
double Negate(double x) { return -x; }
double Identity(double x) { return x; }

absl::Status ParserError(const std::string& what, const std::string& text,
                         const mu::Parser::exception_type& e) {
  // Most of muparser's messages already say "at position N"; add the
  // position only to those that do not.
  std::string message(absl::StripSuffix(e.GetMsg(), "."));
  if (message.find("position") == std::string::npos && e.GetPos() >= 0) {
    absl::StrAppendFormat(&message, " at position %d", e.GetPos());
  }
  return absl::InvalidArgumentError(absl::StrFormat("%s: %s in \"%s\"", what, message, text));
}

absl::Status Unsupported(const std::string& what, const std::string& text,
                         const std::string& construct) {
  std::vector<std::string> names;
  for (const Builtin& f : kBuiltins) names.push_back(f.name);
  return absl::InvalidArgumentError(absl::StrFormat(
      "%s: %s is not supported in \"%s\"; expressions use numbers, the variables, _pi, _e, "
      "+ - * / ^, < > <= >= == !=, && ||, c ? a : b and the functions %s",
      what, construct, text, absl::StrJoin(names, " ")));
}

// Translates muparser's bytecode into our program. `vars` is the array the
// parser's variables point into.
absl::StatusOr<std::vector<Instruction>> Translate(const mu::ParserByteCode& bytecode,
                                                   const double* vars, int var_count,
                                                   const std::string& what,
                                                   const std::string& text) {
  const mu::SToken* tokens = bytecode.GetBase();
  const size_t size = bytecode.GetSize();
  std::vector<Instruction> code;
  int depth = 0, max_depth = 0;
  // Open conditionals: the index of their kIf (then kElse) and the depth
  // before the then-branch (then after it).
  std::vector<std::pair<int, int>> open_if, open_else;
  auto internal = [&](const char* why) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: \"%s\" could not be compiled (%s); please report this expression", what, text, why));
  };
  auto var_index = [&](const double* p) {
    return p >= vars && p < vars + var_count ? p - vars : -1;
  };
  auto emit = [&](Op op, int pops, int pushes, int32_t arg = 0, double a = 0, double b = 0,
                  Fn fn = Fn::kNone) {
    code.push_back({op, fn, arg, a, b});
    depth += pushes - pops;
    max_depth = std::max(max_depth, depth);
  };
  for (size_t i = 0; i < size && tokens[i].Cmd != mu::cmEND; ++i) {
    const mu::SToken& t = tokens[i];
    switch (t.Cmd) {
      case mu::cmVAL:
        emit(Op::kConst, 0, 1, 0, t.Val.data2);
        continue;
      case mu::cmVAR:
      case mu::cmVARPOW2:
      case mu::cmVARPOW3:
      case mu::cmVARPOW4:
      case mu::cmVARMUL: {
        const int index = static_cast<int>(var_index(t.Val.ptr));
        if (index < 0) return internal("a variable outside the known ones");
        const Op op = t.Cmd == mu::cmVAR       ? Op::kVar
                      : t.Cmd == mu::cmVARPOW2 ? Op::kVarSquare
                      : t.Cmd == mu::cmVARPOW3 ? Op::kVarCube
                      : t.Cmd == mu::cmVARPOW4 ? Op::kVarFourth
                                               : Op::kVarMulAdd;
        emit(op, 0, 1, index, t.Val.data, t.Val.data2);
        continue;
      }
      case mu::cmLE:
      case mu::cmGE:
      case mu::cmNEQ:
      case mu::cmEQ:
      case mu::cmLT:
      case mu::cmGT:
      case mu::cmADD:
      case mu::cmSUB:
      case mu::cmMUL:
      case mu::cmDIV:
      case mu::cmPOW:
      case mu::cmLAND:
      case mu::cmLOR: {
        static constexpr Op kBinary[] = {
            Op::kLessEqual, Op::kGreaterEqual, Op::kNotEqual, Op::kEqual, Op::kLess,
            Op::kGreater,   Op::kAdd,          Op::kSub,      Op::kMul,   Op::kDiv,
            Op::kPow,       Op::kAnd,          Op::kOr};
        if (depth < 2) return internal("an operator without two operands");
        emit(kBinary[t.Cmd - mu::cmLE], 2, 1);
        continue;
      }
      case mu::cmIF:
        if (depth < 1) return internal("a condition without a value");
        emit(Op::kIf, 1, 0);
        open_if.push_back({static_cast<int>(code.size()) - 1, depth});
        continue;
      case mu::cmELSE: {
        if (open_if.empty()) return internal("':' without '?'");
        const auto [if_pc, depth_before] = open_if.back();
        open_if.pop_back();
        if (depth != depth_before + 1) return internal("a then-branch without one value");
        code[if_pc].arg = static_cast<int32_t>(code.size());
        emit(Op::kElse, 0, 0);
        open_else.push_back({static_cast<int>(code.size()) - 1, depth});
        depth = depth_before;
        continue;
      }
      case mu::cmENDIF: {
        if (open_else.empty()) return internal("an unmatched end of a conditional");
        const auto [else_pc, depth_then] = open_else.back();
        open_else.pop_back();
        if (depth != depth_then) return internal("an else-branch without one value");
        code[else_pc].arg = static_cast<int32_t>(code.size());
        emit(Op::kEndIf, 0, 0);
        continue;
      }
      case mu::cmFUNC: {
        const int argc = t.Fun.argc;
        const void* data = t.Fun.cb._pUserData;
        if (data == nullptr) {  // the infix operators
          if (argc != 1 || depth < 1) return internal("a malformed unary operator");
          if (t.Fun.cb._pRawFun == reinterpret_cast<mu::erased_fun_type>(&Negate)) {
            emit(Op::kFunc, 1, 1, 0, 0, 0, Fn::kNeg);
          } else if (t.Fun.cb._pRawFun != reinterpret_cast<mu::erased_fun_type>(&Identity)) {
            return internal("an unknown operator");
          }
          continue;
        }
        const Builtin* f = nullptr;
        for (const Builtin& b : kBuiltins) {
          if (&b == data) f = &b;
        }
        if (f == nullptr) return internal("an unknown function");
        if (f->arity < 0) {
          const int n = -argc;
          if (n < 1 || depth < n) return internal("a malformed argument list");
          emit(f->op, n, 1, n);
        } else {
          if (argc != f->arity || depth < argc) return internal("a malformed argument list");
          emit(f->op, argc, 1, 0, 0, 0, f->fn);
        }
        continue;
      }
      case mu::cmASSIGN:
        return Unsupported(what, text, "assignment (=)");
      default:
        return Unsupported(what, text, absl::StrFormat("muparser opcode %d", t.Cmd));
    }
  }
  if (!open_if.empty() || !open_else.empty()) return internal("an unfinished conditional");
  if (depth != 1) return internal("not exactly one result");
  if (max_depth > kMaxStack) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: \"%s\" needs %d pending values at once, more than the %d supported; split long "
        "sums or nest less deeply",
        what, text, max_depth, kMaxStack));
  }
  return code;
}

}  // namespace

Expression::Expression(std::string text, std::vector<Instruction> code)
    : text_(std::move(text)), code_(std::move(code)), straight_(!HasConditionals(code_)) {}

Expression::~Expression() = default;

absl::StatusOr<std::unique_ptr<Expression>> Expression::Compile(
    std::string what, std::string text, std::vector<std::string> variables) {
  if (absl::StripAsciiWhitespace(text).empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s is empty; write an expression%s", what,
        variables.empty() ? "" : absl::StrCat(" in ", absl::StrJoin(variables, ", "))));
  }
  // Test values for the variables: the parse evaluates once, and the
  // translation is checked against muparser at a few points below.
  std::vector<double> values(variables.size(), 0.5);
  mu::Parser parser;
  try {
    parser.ClearFun();
    parser.ClearConst();
    parser.ClearInfixOprt();
    parser.ClearPostfixOprt();
    parser.ClearOprt();
    for (const Builtin& f : kBuiltins) {
      void* data = const_cast<Builtin*>(&f);
      if (f.op == Op::kFunc) {
        parser.DefineFunUserData(f.name, &CallUnary, data);
      } else if (f.op == Op::kAtan2) {
        parser.DefineFunUserData(f.name, &CallAtan2, data);
      } else {
        parser.DefineFunUserData(f.name, &CallMulti, data);
      }
    }
    parser.DefineInfixOprt("-", &Negate);
    parser.DefineInfixOprt("+", &Identity);
    parser.DefineConst("_pi", kPi);
    parser.DefineConst("_e", kE);
    for (size_t i = 0; i < variables.size(); ++i) parser.DefineVar(variables[i], &values[i]);
    parser.SetExpr(text);
    parser.Eval();  // parses now, so syntax errors surface here
    if (parser.GetNumResults() != 1) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: \"%s\" has %d comma-separated results; give a single expression", what, text,
          parser.GetNumResults()));
    }
  } catch (const mu::Parser::exception_type& e) {
    return ParserError(what, text, e);
  }
  std::vector<Instruction> code;
  {
    auto translated =
        Translate(parser.GetByteCode(), values.data(), static_cast<int>(values.size()), what, text);
    if (!translated.ok()) return translated.status();
    code = *std::move(translated);
  }
  // The translation must reproduce muparser: to rounding, since our
  // elementary functions are SLEEF's (core/vector_math.h) and muparser's the
  // C library's. A mistranslation (an operator, an argument order) is off by
  // far more.
  for (const double probe : {0.5, 0.2113248654, 0.7886751346}) {
    for (size_t i = 0; i < values.size(); ++i) values[i] = probe + 0.0123 * i;
    double theirs;
    try {
      theirs = parser.Eval();
    } catch (const mu::Parser::exception_type& e) {
      return ParserError(what, text, e);
    }
    const double ours = Run(code, values.data());
    const bool close = std::fabs(ours - theirs) <= 1e-9 * std::max(1.0, std::fabs(theirs));
    if (!(ours == theirs || close || (std::isnan(ours) && std::isnan(theirs)))) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: \"%s\" could not be compiled faithfully (%.17g instead of %.17g); please report "
          "this expression",
          what, text, ours, theirs));
    }
  }
  return std::unique_ptr<Expression>(new Expression(std::move(text), std::move(code)));
}

size_t Expression::program_size() const { return code_.size(); }

bool Expression::Uses(size_t i) const {
  for (const Instruction& in : code_) {
    const bool reads = in.op == Op::kVar || in.op == Op::kVarMulAdd || in.op == Op::kVarSquare ||
                       in.op == Op::kVarCube || in.op == Op::kVarFourth;
    if (reads && in.arg == static_cast<int32_t>(i)) return true;
  }
  return false;
}

double Expression::Evaluate(const double* values) const { return Run(code_, values); }
Dual1 Expression::Evaluate(const Dual1* values) const { return Run(code_, values); }
Dual2 Expression::Evaluate(const Dual2* values) const { return Run(code_, values); }
Interval Expression::Evaluate(const Interval* values) const { return Run(code_, values); }
double Expression::Evaluate(const double* values, TrigCache* cache) const {
  return Run(code_, values, cache);
}
Dual1 Expression::Evaluate(const Dual1* values, TrigCache* cache) const {
  return Run(code_, values, cache);
}
Dual2 Expression::Evaluate(const Dual2* values, TrigCache* cache) const {
  return Run(code_, values, cache);
}

void Expression::EvaluateMany(const double* const* columns, size_t variables, size_t n,
                              double* out) const {
  if (!straight_) {
    std::vector<double> values(variables);
    for (size_t k = 0; k < n; ++k) {
      for (size_t i = 0; i < variables; ++i) values[i] = columns[i][k];
      out[k] = Run(code_, values.data());
    }
    return;
  }
  double st[kMaxStack][kBatch];
  std::vector<const double*> vars(columns, columns + variables);
  for (size_t at = 0; at < n; at += kBatch) {
    const size_t m = std::min(kBatch, n - at);
    ExecuteMany(code_, vars.data(), m, st);
    std::copy_n(st[0], m, out + at);
    for (const double*& column : vars) column += m;
  }
}

void TrigCache::SinCos(double x, double* s, double* c) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);  // -0.0 and 0.0 differ in sin
  for (int i = 0; i < size_; ++i) {
    if (bits_[i] == bits) {
      *s = sin_[i], *c = cos_[i];
      return;
    }
  }
  SinCosOf(x, s, c);
  const int slot = next_;
  next_ = (next_ + 1) % kSize;
  size_ = std::max(size_, slot + 1);
  bits_[slot] = bits, sin_[slot] = *s, cos_[slot] = *c;
}

absl::StatusOr<double> EvaluateConstant(const std::string& what, const std::string& text) {
  auto expr = Expression::Compile(what, text, {});
  if (!expr.ok()) return expr.status();
  const double value = (*expr)->Evaluate(static_cast<const double*>(nullptr));
  if (!std::isfinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s: \"%s\" is not a finite number", what, text));
  }
  return value;
}

}  // namespace sfc
