#include "cad/nurbs_patch.h"

#include <cmath>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "base/echo.h"
#include "base/status_macros.h"

namespace sfc::cad {
namespace {

class Parser {
 public:
  explicit Parser(absl::string_view name) : name_(Echo(name, kMaxNameEcho)) {}

  absl::Status Error(int line, absl::string_view what) const {
    if (line > 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("NURBS patch ", name_, ", line ", line, ": ", what));
    }
    return absl::InvalidArgumentError(absl::StrCat("NURBS patch ", name_, ": ", what));
  }

  absl::StatusOr<double> Number(int line, absl::string_view token, absl::string_view what) const {
    double value;
    if (!absl::SimpleAtod(token, &value)) {
      return Error(line, absl::StrCat(what, ": '", Echo(token), "' is not a number"));
    }
    if (!std::isfinite(value)) {
      return Error(
          line, absl::StrCat(what, " is ", Echo(token), " (NaN or infinite); give finite numbers"));
    }
    return value;
  }

  absl::StatusOr<int> Integer(int line, absl::string_view token, absl::string_view what) const {
    int value;
    if (!absl::SimpleAtoi(token, &value)) {
      return Error(line, absl::StrCat(what, ": '", Echo(token), "' is not an integer"));
    }
    return value;
  }

  // Checks one full knot vector for a clamped, non-periodic B-spline.
  absl::Status CheckKnots(const std::vector<double>& knots, int degree, int count, int line,
                          absl::string_view axis) const {
    const size_t expected = static_cast<size_t>(count) + degree + 1;
    if (knots.size() != expected) {
      return Error(line, absl::StrCat("knots_", axis, " has ", knots.size(), " knots; ", count,
                                      " control points of degree ", degree,
                                      " need count + degree + 1 = ", expected));
    }
    for (size_t i = 1; i < knots.size(); ++i) {
      if (knots[i] < knots[i - 1]) {
        return Error(line,
                     absl::StrCat("knots_", axis, " decreases at position ", i, " (", knots[i - 1],
                                  " then ", knots[i], "); knots must be non-decreasing"));
      }
    }
    if (!(knots.front() < knots.back())) {
      return Error(line, absl::StrCat("knots_", axis, " spans an empty parameter range"));
    }
    size_t i = 0;
    while (i < knots.size()) {
      size_t j = i;
      while (j < knots.size() && knots[j] == knots[i]) ++j;
      const int multiplicity = static_cast<int>(j - i);
      const bool end = i == 0 || j == knots.size();
      if (end && multiplicity != degree + 1) {
        return Error(
            line, absl::StrCat("knots_", axis, ": the end knot ", knots[i], " has multiplicity ",
                               multiplicity, "; ends must be clamped (multiplicity degree + 1 = ",
                               degree + 1, ")"));
      }
      if (!end && multiplicity > degree) {
        return Error(
            line, absl::StrCat("knots_", axis, ": the interior knot ", knots[i],
                               " has multiplicity ", multiplicity, ", above the degree ", degree));
      }
      i = j;
    }
    return absl::OkStatus();
  }

 private:
  std::string name_;
};

}  // namespace

absl::StatusOr<NurbsPatch> ParseNurbsPatch(absl::string_view text, absl::string_view name) {
  Parser parser(name);
  NurbsPatch patch;
  bool have_header = false, have_degree = false, have_count = false;
  int knots_u_line = 0, knots_v_line = 0;
  bool have_knots_u = false, have_knots_v = false;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    if (size_t hash = line.find('#'); hash != absl::string_view::npos) line = line.substr(0, hash);
    std::vector<absl::string_view> tokens =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    if (tokens.empty()) continue;
    const absl::string_view key = tokens[0];
    if (!have_header) {
      if (key != "sfcsampler-nurbs" || tokens.size() != 2 || tokens[1] != "1") {
        return parser.Error(line_number, "the first line must be 'sfcsampler-nurbs 1'");
      }
      have_header = true;
      continue;
    }
    if (key == "degree" || key == "count") {
      if (tokens.size() != 3)
        return parser.Error(line_number,
                            absl::StrCat("'", Echo(key), "' takes two integers (u, v)"));
      ASSIGN_OR_RETURN(int a, parser.Integer(line_number, tokens[1], key));
      ASSIGN_OR_RETURN(int b, parser.Integer(line_number, tokens[2], key));
      if (key == "degree") {
        if (have_degree) return parser.Error(line_number, "'degree' given twice");
        if (a < 1 || b < 1 || a > kMaxNurbsDegree || b > kMaxNurbsDegree) {
          return parser.Error(line_number, absl::StrCat("degrees must be in [1, ", kMaxNurbsDegree,
                                                        "], got ", a, " ", b));
        }
        patch.degree_u = a, patch.degree_v = b, have_degree = true;
      } else {
        if (have_count) return parser.Error(line_number, "'count' given twice");
        if (a < 2 || b < 2 || a > 10000 || b > 10000) {
          return parser.Error(
              line_number,
              absl::StrCat("control point counts must be in [2, 10000], got ", a, " ", b));
        }
        patch.count_u = a, patch.count_v = b, have_count = true;
      }
    } else if (key == "knots_u" || key == "knots_v") {
      const bool u = key == "knots_u";
      if (u ? have_knots_u : have_knots_v)
        return parser.Error(line_number, absl::StrCat("'", key, "' given twice"));
      std::vector<double>& knots = u ? patch.knots_u : patch.knots_v;
      for (size_t i = 1; i < tokens.size(); ++i) {
        ASSIGN_OR_RETURN(double k,
                         parser.Number(line_number, tokens[i], absl::StrCat(key, "[", i - 1, "]")));
        knots.push_back(k);
      }
      (u ? have_knots_u : have_knots_v) = true;
      (u ? knots_u_line : knots_v_line) = line_number;
    } else if (key == "pole") {
      if (tokens.size() != 4 && tokens.size() != 5) {
        return parser.Error(line_number, "'pole' takes x y z and an optional weight w");
      }
      NurbsPatch::Pole pole{0, 0, 0, 1};
      const char* names[] = {"x", "y", "z", "weight"};
      double* fields[] = {&pole.x, &pole.y, &pole.z, &pole.w};
      for (size_t i = 1; i < tokens.size(); ++i) {
        ASSIGN_OR_RETURN(
            *fields[i - 1],
            parser.Number(line_number, tokens[i],
                          absl::StrCat("control point ", patch.poles.size(), " ", names[i - 1])));
      }
      if (!(pole.w > 0)) {
        return parser.Error(
            line_number, absl::StrCat("control point ", patch.poles.size(), " has weight ", pole.w,
                                      "; weights must be positive"));
      }
      patch.poles.push_back(pole);
    } else {
      return parser.Error(line_number,
                          absl::StrCat("unknown keyword '", Echo(key),
                                       "' (expected degree, count, knots_u, knots_v or pole)"));
    }
  }
  if (!have_header) return parser.Error(0, "empty; the first line must be 'sfcsampler-nurbs 1'");
  if (!have_degree) return parser.Error(0, "no 'degree' line");
  if (!have_count) return parser.Error(0, "no 'count' line");
  if (!have_knots_u) return parser.Error(0, "no 'knots_u' line");
  if (!have_knots_v) return parser.Error(0, "no 'knots_v' line");
  RETURN_IF_ERROR(
      parser.CheckKnots(patch.knots_u, patch.degree_u, patch.count_u, knots_u_line, "u"));
  RETURN_IF_ERROR(
      parser.CheckKnots(patch.knots_v, patch.degree_v, patch.count_v, knots_v_line, "v"));
  const size_t expected = static_cast<size_t>(patch.count_u) * patch.count_v;
  if (patch.poles.size() != expected) {
    return parser.Error(0, absl::StrCat(patch.poles.size(), " control points; count ",
                                        patch.count_u, " x ", patch.count_v, " needs ", expected));
  }
  return patch;
}

}  // namespace sfc::cad
