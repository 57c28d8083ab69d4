#include "cad/preflight.h"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "base/echo.h"
#include "base/status_macros.h"

namespace sfc::cad {
namespace {

// 1-based line number of byte `at`.
uint64_t LineOf(absl::string_view bytes, size_t at) {
  return 1 + static_cast<uint64_t>(std::count(bytes.begin(), bytes.begin() + at, '\n'));
}

// Where the string that OpenCASCADE's lexer reads from the quote at `at`
// ends (its closing quote), or npos when the lexer reads no string there: a
// string runs to the next quote not doubled, through any byte but 0x01-0x08,
// 0x7f and 0x80 (its rule in StepFile/step.lex).
size_t LexerStringEnd(absl::string_view bytes, size_t at) {
  for (size_t i = at + 1; i < bytes.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    if (c == '\'') {
      if (i + 1 < bytes.size() && bytes[i + 1] == '\'') {
        ++i;
        continue;
      }
      return i;
    }
    if ((c >= 0x01 && c <= 0x08) || c == 0x7f || c == 0x80) return absl::string_view::npos;
  }
  return absl::string_view::npos;
}

// True at the lexer's end-of-exchange token: END-ISO, digits and dashes,
// then ';', not inside a longer word.
bool IsEndOfExchange(absl::string_view bytes, size_t at) {
  if (at > 0 && (absl::ascii_isalnum(bytes[at - 1]) || bytes[at - 1] == '_')) return false;
  if (!absl::StartsWith(bytes.substr(at), "END-ISO")) return false;
  size_t i = at + 7;
  while (i < bytes.size() && (absl::ascii_isdigit(bytes[i]) || bytes[i] == '-')) ++i;
  return i < bytes.size() && bytes[i] == ';';
}

// `text` without its leading blanks and comments (a comment ends at the
// first "*/" outside a string the lexer reads in it).
absl::string_view SkipBlanksAndComments(absl::string_view text) {
  for (;;) {
    text = absl::StripLeadingAsciiWhitespace(text);
    if (!absl::StartsWith(text, "/*")) return text;
    size_t i = 2;
    while (i < text.size() && !(text[i] == '*' && i + 1 < text.size() && text[i + 1] == '/')) {
      const size_t end = text[i] == '\'' ? LexerStringEnd(text, i) : absl::string_view::npos;
      i = end == absl::string_view::npos ? i + 1 : end + 1;
    }
    text = i < text.size() ? text.substr(i + 2) : absl::string_view();
  }
}

// The record's "#N = KEYWORD(" head, when it has one: its number and
// keyword. Comments may stand between the tokens.
bool ParseHead(absl::string_view record, uint64_t* id, absl::string_view* keyword) {
  record = SkipBlanksAndComments(record);
  if (record.empty() || record[0] != '#') return false;
  size_t i = 1;
  while (i < record.size() && absl::ascii_isdigit(record[i])) ++i;
  if (!absl::SimpleAtoi(record.substr(1, i - 1), id)) return false;
  record = SkipBlanksAndComments(record.substr(i));
  if (record.empty() || record[0] != '=') return false;
  record = SkipBlanksAndComments(record.substr(1));
  size_t j = 0;
  while (j < record.size() && (absl::ascii_isalnum(record[j]) || record[j] == '_')) ++j;
  *keyword = record.substr(0, j);
  return j > 0;
}

// True when `token` (blanks around it ignored) is an IGES integer or real:
// [+-]digits[.digits][E|D[+-]digits], or .digits; or empty (a default).
bool IsIgesNumber(absl::string_view token) {
  token = absl::StripAsciiWhitespace(token);
  size_t i = 0;
  if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
  size_t digits = 0;
  while (i < token.size() && absl::ascii_isdigit(token[i])) ++i, ++digits;
  if (i < token.size() && token[i] == '.') {
    ++i;
    while (i < token.size() && absl::ascii_isdigit(token[i])) ++i, ++digits;
  }
  if (digits == 0) return token.empty();
  if (i < token.size() &&
      (token[i] == 'E' || token[i] == 'e' || token[i] == 'D' || token[i] == 'd')) {
    ++i;
    if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
    size_t exponent = 0;
    while (i < token.size() && absl::ascii_isdigit(token[i])) ++i, ++exponent;
    if (exponent == 0) return false;
  }
  return i == token.size();
}

// Checks every parameter of the parameter data (columns 1-64 of the P lines,
// in order, `lines` their line numbers): each is a number, empty, or a
// Hollerith string nH followed by n characters. OpenCASCADE reads a damaged
// number such as "0&" without a complaint its transfer heeds, and its shape
// healing can then loop for good (iges_fuzzer found one).
absl::Status CheckIgesParameters(absl::string_view data, const std::vector<uint64_t>& lines,
                                 char parameter_delimiter, char record_delimiter) {
  size_t i = 0;
  while (i < data.size()) {
    size_t j = i;
    while (j < data.size() && data[j] != parameter_delimiter && data[j] != record_delimiter) ++j;
    absl::string_view token = data.substr(i, j - i);
    const absl::string_view stripped = absl::StripLeadingAsciiWhitespace(token);
    size_t h = 0;
    while (h < stripped.size() && absl::ascii_isdigit(stripped[h])) ++h;
    uint64_t length = 0;
    if (h > 0 && h < stripped.size() && (stripped[h] == 'H' || stripped[h] == 'h') &&
        absl::SimpleAtoi(stripped.substr(0, h), &length)) {
      // A Hollerith string: its characters may hold delimiters.
      const size_t text = static_cast<size_t>(stripped.data() - data.data()) + h + 1;
      if (length > data.size() - std::min(text, data.size())) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "parameter data line %d: the string '%s' runs past the end of the file",
            lines[std::min(i / 64, lines.size() - 1)], Echo(stripped, 24)));
      }
      j = text + length;
      const size_t after = j;
      while (j < data.size() && data[j] == ' ') ++j;
      if (j < data.size() && data[j] != parameter_delimiter && data[j] != record_delimiter) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "parameter data line %d: a string of %d characters is followed by '%s', not a "
            "delimiter; the file is damaged (fix or re-export it)",
            lines[std::min(after / 64, lines.size() - 1)], length,
            Echo(data.substr(after, 8), 16)));
      }
    } else if (!IsIgesNumber(token)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "parameter data line %d: '%s' is not a number; the file is damaged (fix or re-export it)",
          lines[std::min(i / 64, lines.size() - 1)], Echo(absl::StripAsciiWhitespace(token), 40)));
    }
    i = j + 1;
    // After a record's end, the rest of its last line is padding (a comment).
    if (j < data.size() && data[j] == record_delimiter) i = (j / 64 + 1) * 64;
  }
  return absl::OkStatus();
}

// Every entity instance name is defined once, as ISO 10303-21 requires, and
// fits an int, as the reader keeps it (atoi: a larger one wraps onto
// another name). OpenCASCADE 7.6 resolves a name defined twice in a second
// pass (StepData_StepReaderData::SetEntityNumbers) that reads arrays it
// never initialised: what it does then depends on what earlier allocations
// left in the heap, from returning at once to looping for good (step_fuzzer
// found files that read in 0.1 s in a fresh process and never ended after
// others). A definition is what the reader's lexer takes for one, "#N" then
// blanks then "=", looked for everywhere, strings and comments included:
// where the lexer's idea of a string differs from the standard's (it ends
// one at a control character), a definition hidden in a "string" would
// otherwise slip through.
absl::Status CheckEntityNames(absl::string_view bytes) {
  struct NameAt {
    uint64_t id;
    size_t at;
  };
  std::vector<NameAt> names;
  for (size_t i = bytes.find('#'); i != absl::string_view::npos; i = bytes.find('#', i)) {
    const size_t at = i++;
    const size_t digits = i;
    while (i < bytes.size() && absl::ascii_isdigit(bytes[i])) ++i;
    if (i == digits) continue;
    size_t j = i;
    while (j < bytes.size() && (absl::ascii_isspace(bytes[j]) || bytes[j] == '\0')) ++j;
    if (j == bytes.size() || bytes[j] != '=') continue;
    const absl::string_view number = bytes.substr(digits, i - digits);
    uint64_t id = 0;
    if (!absl::SimpleAtoi(number, &id) || id > uint64_t{std::numeric_limits<int32_t>::max()}) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the entity name #%s at line %d is out of range (at most #%d); the file is damaged "
          "(fix or re-export it)",
          Echo(number, 24), LineOf(bytes, at), std::numeric_limits<int32_t>::max()));
    }
    names.push_back({id, at});
  }
  std::sort(names.begin(), names.end(), [](const NameAt& a, const NameAt& b) {
    return a.id != b.id ? a.id < b.id : a.at < b.at;
  });
  const auto twice = std::adjacent_find(
      names.begin(), names.end(), [](const NameAt& a, const NameAt& b) { return a.id == b.id; });
  if (twice == names.end()) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrFormat(
      "the entity name #%d is defined twice, at lines %d and %d (strings and comments count); "
      "names must be unique (fix or re-export the file)",
      twice->id, LineOf(bytes, twice->at), LineOf(bytes, std::next(twice)->at)));
}

}  // namespace

absl::StatusOr<ModelCensus> PreflightStep(absl::string_view bytes, const PreflightLimits& limits) {
  ModelCensus census;
  int depth = 0;
  size_t record_start = 0;
  bool comment = false;
  for (size_t i = 0; i < bytes.size(); ++i) {
    const char c = bytes[i];
    // Strings and comments as OpenCASCADE's lexer reads them: a string is
    // lexed inside a comment too (and can hide its "*/"), and a quote that
    // starts no string the lexer accepts is a character like any other.
    if (c == '\'') {
      const size_t end = LexerStringEnd(bytes, i);
      if (end != absl::string_view::npos) i = end;
    } else if (c == '/' && i + 1 < bytes.size() && bytes[i + 1] == '*') {
      comment = true;
      ++i;
    } else if (c == '*' && i + 1 < bytes.size() && bytes[i + 1] == '/') {
      comment = false;
      ++i;
    } else if (comment) {
      // Nothing inside a comment counts, but its length.
    } else if (c == 'E' && IsEndOfExchange(bytes, i)) {
      break;  // the lexer reads nothing after END-ISO-10303-21;
    } else if (c == '(') {
      if (++depth > limits.max_nesting) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "parentheses nest deeper than %d at line %d (max_nesting; real models nest at most "
            "5 deep): the record starting '%s' is malformed, fix or re-export the file",
            limits.max_nesting, LineOf(bytes, i),
            Echo(absl::StripLeadingAsciiWhitespace(bytes.substr(record_start, 40)))));
      }
      census.max_nesting = std::max(census.max_nesting, depth);
    } else if (c == ')') {
      // The reader's recovery from unbalanced parentheses sent it into the
      // uninitialised pass of SetEntityNumbers too (step_fuzzer); it refuses
      // such files anyway, so they are refused here, before it runs.
      if (depth == 0) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "line %d: a ')' closes no '(' in the record starting '%s'; the file is damaged (fix "
            "or re-export it)",
            LineOf(bytes, i),
            Echo(absl::StripLeadingAsciiWhitespace(bytes.substr(record_start, 40)))));
      }
      --depth;
    } else if (c == ';' && depth > 0) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "line %d: the record starting '%s' ends with %d '(' still open; the file is damaged "
          "(fix or re-export it)",
          LineOf(bytes, i), Echo(absl::StripLeadingAsciiWhitespace(bytes.substr(record_start, 40))),
          depth));
    }
    const size_t length = i + 1 - record_start;
    if (length > limits.max_record_bytes) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the record at line %d, starting '%s', is longer than %d bytes (max_record_bytes): a "
          "missing ';' or a broken file; fix or re-export it",
          LineOf(bytes, record_start),
          Echo(absl::StripLeadingAsciiWhitespace(bytes.substr(record_start, 40))),
          limits.max_record_bytes));
    }
    if (i < bytes.size() && bytes[i] == ';' && !comment) {
      const absl::string_view record =
          absl::StripAsciiWhitespace(bytes.substr(record_start, i - record_start));
      census.longest_record = std::max<uint64_t>(census.longest_record, record.size());
      uint64_t id = 0;
      absl::string_view keyword;
      // Any record with a "#N =" head is an entity instance, in whichever section.
      if (ParseHead(record, &id, &keyword)) {
        if (++census.entities > limits.max_entities) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "the file has more than %d entity instances (max_entities); split the model",
              limits.max_entities));
        }
        const std::string upper = absl::AsciiStrToUpper(keyword);
        if (upper == "ADVANCED_FACE" || upper == "FACE_SURFACE") {
          census.faces.push_back(absl::StrCat("#", id, " ", upper));
          census.face_ids.push_back(id);
        }
      }
      depth = 0;
      record_start = i + 1;
    }
  }
  RETURN_IF_ERROR(CheckEntityNames(bytes));
  return census;
}

absl::StatusOr<ModelCensus> PreflightIges(absl::string_view bytes, const PreflightLimits& limits) {
  ModelCensus census;
  uint64_t line_number = 0;
  bool first_of_entry = true;
  std::string global, parameters;  // the G lines' columns 1-72, the P lines' 1-64
  std::vector<uint64_t> parameter_lines;
  size_t start = 0;
  while (start < bytes.size()) {
    size_t end = bytes.find('\n', start);
    if (end == absl::string_view::npos) end = bytes.size();
    absl::string_view line = bytes.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    // Writers may pad past column 80 with blanks; anything else is too long.
    const absl::string_view text = line.size() > limits.max_iges_line
                                       ? absl::StripTrailingAsciiWhitespace(line)
                                       : line;
    census.longest_record = std::max<uint64_t>(census.longest_record, text.size());
    if (text.size() > limits.max_iges_line) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "line %d has %d characters; IGES records have %d columns (max_iges_line), so the file "
          "is broken or not IGES: '%s'",
          line_number, text.size(), limits.max_iges_line, Echo(text, 40)));
    }
    if (line.size() >= 73 && line[72] == 'G' && global.size() < (uint64_t{1} << 20)) {
      absl::StrAppend(&global, line.substr(0, 72));
    }
    if (line.size() >= 73 && line[72] == 'P') {
      // Columns 1-64, blank-padded: a string's count runs across lines.
      std::string field(line.substr(0, 64));
      field.resize(64, ' ');
      parameters += field;
      parameter_lines.push_back(line_number);
    }
    if (line.size() < 73 || line[72] != 'D') continue;
    // Directory entries take two lines; the first holds the type (columns
    // 1-8), the status (65-72) and the sequence number (74-80).
    if (!first_of_entry) {
      first_of_entry = true;
      continue;
    }
    first_of_entry = false;
    if (++census.entities > limits.max_entities) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the file has more than %d directory entries (max_entities); split the model",
          limits.max_entities));
    }
    int type = 0;
    uint64_t sequence = 0;
    if (!absl::SimpleAtoi(absl::StripAsciiWhitespace(line.substr(0, 8)), &type)) continue;
    if (!absl::SimpleAtoi(absl::StripAsciiWhitespace(line.substr(73, 7)), &sequence)) continue;
    const absl::string_view status = line.substr(64, 8);
    const bool independent = status.size() == 8 && status.substr(2, 2) == "00";
    const bool face = type == 510 || type == 144 || type == 143;
    const bool surface = type == 128 || type == 114 || type == 118 || type == 120 || type == 122 ||
                         type == 140 || (type >= 190 && type <= 198 && type % 2 == 0);
    if (face || (surface && independent)) {
      census.faces.push_back(absl::StrCat("DE ", sequence, " type ", type));
      census.face_ids.push_back(sequence);
    }
  }
  // The delimiters: the global section's first two fields ("1H," and "1H;"
  // by default; an empty field keeps the default).
  char parameter_delimiter = ',', record_delimiter = ';';
  absl::string_view g = absl::StripLeadingAsciiWhitespace(global);
  if (absl::StartsWith(g, "1H") && g.size() >= 3) {
    parameter_delimiter = g[2];
    g.remove_prefix(3);
  }
  if (!g.empty() && g[0] == parameter_delimiter) g.remove_prefix(1);
  g = absl::StripLeadingAsciiWhitespace(g);
  if (absl::StartsWith(g, "1H") && g.size() >= 3) record_delimiter = g[2];
  RETURN_IF_ERROR(CheckIgesParameters(parameters, parameter_lines, parameter_delimiter,
                                      record_delimiter));
  return census;
}

}  // namespace sfc::cad
