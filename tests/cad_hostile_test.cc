// Hostile and damaged CAD files (issue 21): what OpenCASCADE's readers cannot
// survive is refused before they see it (cad/preflight.h), and what they drop
// is noticed after (Load compares the file's face entities with the faces it
// got). Every file is made here from the project's fixtures.
#include <algorithm>
#include <random>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "cad/fixtures.h"
#include "cad/load.h"
#include "cad/preflight.h"
#include "gtest/gtest.h"
#include "tests/cad_test_util.h"

namespace sfc::cad {
namespace {

using fixtures::Solid;

using testing::Bytes;

std::string StepWithData(const std::string& data) {
  return absl::StrCat(
      "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
      "FILE_NAME('','',(''),(''),'','','');\n"
      "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n",
      data, "ENDSEC;\nEND-ISO-10303-21;\n");
}

// A point whose coordinate list nests `depth` parentheses deep.
std::string NestedPoint(int depth) {
  return StepWithData(absl::StrCat("#1 = CARTESIAN_POINT('',", std::string(depth, '('), "0.",
                                   std::string(depth, ')'), ");\n"));
}

void ExpectRefused(const absl::StatusOr<std::shared_ptr<const Model>>& model,
                   const std::string& needle) {
  ASSERT_FALSE(model.ok()) << "loaded";
  EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
  EXPECT_NE(model.status().message().find(needle), std::string::npos) << model.status();
  EXPECT_LT(model.status().message().size(), 1024u) << model.status();
}

// 100 000 levels overflow the reader's stack (about 65 000 do on an 8 MiB
// thread stack with OCC 7.6): refused before the reader runs, on a thread
// with a small stack too.
TEST(CadHostile, DeepNestingIsRefusedBeforeTheReader) {
  const std::string deep = NestedPoint(100000);
  absl::StatusOr<std::shared_ptr<const Model>> model;
  std::thread([&] { model = Load(ModelFormat::kStep, deep, "deep.step"); }).join();
  ExpectRefused(model, "max_nesting");
  ExpectRefused(model, "deep.step");
  // The limit itself passes the preflight (and the reader then finds no face).
  const PreflightLimits limits;
  EXPECT_TRUE(PreflightStep(NestedPoint(limits.max_nesting - 1), limits).ok());
  EXPECT_FALSE(PreflightStep(NestedPoint(limits.max_nesting), limits).ok());
  ExpectRefused(Load(ModelFormat::kStep, NestedPoint(limits.max_nesting - 1), "ok_depth.step"),
                "not a Real");
  // Parentheses inside strings and comments do not count.
  const std::string quoted = StepWithData(absl::StrCat(
      "#1 = CARTESIAN_POINT('", std::string(1000, '('), "''(',(0.,0.,0.));\n/* ",
      std::string(1000, '('), " */\n"));
  auto census = PreflightStep(quoted, limits);
  ASSERT_TRUE(census.ok()) << census.status();
  EXPECT_EQ(census->max_nesting, 2);
  EXPECT_EQ(census->entities, 1u);
}

TEST(CadHostile, EntityRecordAndLineLimits) {
  const std::string& step = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const std::string& iges = Bytes(Solid::kBoxWithHole, ModelFormat::kIges);
  LoadOptions few;
  few.preflight.max_entities = 10;
  ExpectRefused(Load(ModelFormat::kStep, step, "many.step", few), "max_entities");
  ExpectRefused(Load(ModelFormat::kIges, iges, "many.iges", few), "max_entities");
  LoadOptions short_records;
  short_records.preflight.max_record_bytes = 40;
  ExpectRefused(Load(ModelFormat::kStep, step, "long.step", short_records), "max_record_bytes");
  // A record that never ends (a missing ';') is cut off at the limit, not read to the end.
  std::string unterminated = StepWithData(
      absl::StrCat("#1 = CARTESIAN_POINT('',(0.,0.,0.))", std::string(1 << 20, ' '), "\n"));
  ExpectRefused(Load(ModelFormat::kStep, unterminated, "open.step", short_records),
                "max_record_bytes");
  // An IGES line past column 80 (a million characters here).
  std::string long_line = iges;
  long_line.insert(long_line.find('\n'), std::string(1 << 20, 'x'));
  ExpectRefused(Load(ModelFormat::kIges, long_line, "long.iges"), "max_iges_line");
}

TEST(CadHostile, CensusCountsTheFixturesFaces) {
  const PreflightLimits limits;
  for (const auto& [solid, faces] : {std::pair{Solid::kSphere, 1}, std::pair{Solid::kCylinder, 3},
                                     std::pair{Solid::kBoxWithHole, 8}}) {
    for (ModelFormat format : {ModelFormat::kStep, ModelFormat::kIges}) {
      const std::string& bytes = Bytes(solid, format);
      auto census = format == ModelFormat::kStep ? PreflightStep(bytes, limits)
                                                 : PreflightIges(bytes, limits);
      ASSERT_TRUE(census.ok()) << census.status();
      EXPECT_EQ(census->faces.size(), static_cast<size_t>(faces)) << fixtures::SolidName(solid);
      auto model = Load(format, bytes, fixtures::SolidName(solid));
      ASSERT_TRUE(model.ok()) << model.status();
      EXPECT_EQ((*model)->faces().size(), static_cast<size_t>(faces));
    }
  }
}

// A damaged number in IGES parameter data ("0&" for a coordinate of the
// box's arc made OpenCASCADE 7.6 loop for good in its shape healing; found by
// iges_fuzzer) is refused before the reader runs, naming the line; numbers
// in the spellings IGES allows pass.
TEST(CadHostile, DamagedIgesParametersAreRefusedBeforeTheReader) {
  const std::string& box = Bytes(Solid::kBoxWithHole, ModelFormat::kIges);
  const std::string arc = "100,0.,0.,0.,5.,0.,5.,0.;";
  const size_t at = box.find(arc);
  ASSERT_NE(at, std::string::npos);
  std::string damaged = box;
  damaged.replace(at, arc.size(), "100,0.,0.,0.,5.,0&,5.,0.;");
  ExpectRefused(Load(ModelFormat::kIges, damaged, "arc.iges"), "'0&' is not a number");
  const uint64_t line = 1 + std::count(box.begin(), box.begin() + at, '\n');
  ExpectRefused(Load(ModelFormat::kIges, damaged, "arc.iges"), absl::StrCat("line ", line));

  std::string spellings = box;
  spellings.replace(at, arc.size(), "100,0,-0,.0,5D0,0E0,5.,0;");  // as long as `arc`
  EXPECT_TRUE(PreflightIges(spellings, PreflightLimits{}).ok());
  std::string letters = box;
  letters.replace(at, arc.size(), "100,0.,0.,0.,5.,E5,+5.,0.;");
  EXPECT_FALSE(PreflightIges(letters, PreflightLimits{}).ok());
}

// An entity name defined twice sends OpenCASCADE 7.6 into a pass over arrays
// it never initialised, which can loop for good depending on what is left in
// the heap (step_fuzzer); a name past an int wraps onto another. Both are
// refused before the reader, naming the lines, however the name is written.
// What counts as a definition is what the reader's lexer could take for one.
TEST(CadHostile, EntityNamesDefinedTwiceOrOutOfRangeAreRefused) {
  const std::string& box = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const size_t first = box.find("\n#5 =");
  const size_t second = box.find("\n#12 =");
  ASSERT_NE(first, std::string::npos);
  ASSERT_NE(second, std::string::npos);
  const uint64_t first_line = 2 + std::count(box.begin(), box.begin() + first, '\n');
  const uint64_t second_line = 2 + std::count(box.begin(), box.begin() + second, '\n');
  // The last spelling hides the name behind a quote that OpenCASCADE's lexer
  // does not take for a string's start (a control character follows).
  for (const std::string spelling : {"#5 =", "#005=", "#5\t=", "/* '\x01 */ #5 ="}) {
    std::string twice = box;
    twice.replace(second + 1, 5, spelling);
    ExpectRefused(Load(ModelFormat::kStep, twice, "twice.step"),
                  absl::StrCat("#5 is defined twice, at lines ", first_line, " and ", second_line));
  }
  std::string wraps = box;
  wraps.replace(second + 1, 4, "#4294967301");  // 2^32 + 5: atoi gives 5
  ExpectRefused(Load(ModelFormat::kStep, wraps, "wraps.step"), "#4294967301 at line");
  // The fixtures themselves (every name once) pass.
  EXPECT_TRUE(PreflightStep(box, PreflightLimits{}).ok());
}

// Parentheses must balance in every record, counted as OpenCASCADE's lexer
// reads the file: the reader's recovery from a stray ')' also ran its
// uninitialised pass for good (step_fuzzer), and it refuses such files anyway.
TEST(CadHostile, UnbalancedParenthesesAreRefusedAsTheLexerSeesThem) {
  const std::string& box = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const std::string point = "#12 = CARTESIAN_POINT('',(0.,0.,0.));";
  const size_t at = box.find(point);
  ASSERT_NE(at, std::string::npos);
  const uint64_t line = 1 + std::count(box.begin(), box.begin() + at, '\n');
  std::string stray = box;
  stray.replace(at, point.size(), "#12 = CARTESIAN_POINT('',(0.,0.,0.)));");
  ExpectRefused(Load(ModelFormat::kStep, stray, "stray.step"),
                absl::StrCat("line ", line, ": a ')' closes no '('"));
  std::string open = box;
  open.replace(at, point.size(), "#12 = CARTESIAN_POINT('',(0.,0.;0.));");
  ExpectRefused(Load(ModelFormat::kStep, open, "open.step"), "still open");

  const PreflightLimits limits;
  // A quote followed by a control character starts no string for the lexer,
  // so the parentheses after it count.
  const std::string nested = StepWithData(absl::StrCat(
      "#1 = CARTESIAN_POINT('\x01", std::string(100, '('), "0.", std::string(100, ')'), "');\n"));
  auto deep = PreflightStep(nested, limits);
  ASSERT_FALSE(deep.ok());
  EXPECT_NE(deep.status().message().find("max_nesting"), std::string::npos) << deep.status();
  // A string inside a comment hides a "*/", as it does for the lexer.
  auto commented = PreflightStep(
      StepWithData("/* 'a */ (' */\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\n"), limits);
  ASSERT_TRUE(commented.ok()) << commented.status();
  EXPECT_EQ(commented->entities, 1u);
  // Nothing after the end of the exchange structure is read.
  EXPECT_TRUE(PreflightStep(box + "trailing (( bytes ;", limits).ok());
}

// The first STEP record containing `marker` (e.g. "= ADVANCED_FACE("): where
// the marker is, and the record's entity name "#N"; npos and "" if none.
struct Entity {
  size_t at;
  std::string id;
};
Entity FindEntity(const std::string& step, const std::string& marker) {
  const size_t at = step.find(marker);
  if (at == std::string::npos) return {at, ""};
  const size_t id_start = step.rfind('#', at);
  return {at, step.substr(id_start, step.find(' ', id_start) - id_start)};
}

// A face whose surface reference dangles: the reader drops the face without
// a word; Load names it.
TEST(CadHostile, DanglingReferenceInAFaceIsNamed) {
  std::string step = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const auto [face, id] = FindEntity(step, "= ADVANCED_FACE(");
  ASSERT_NE(face, std::string::npos);
  const size_t end = step.find(';', face);
  const size_t surface = step.rfind("),#", end);  // "(bounds),#SURFACE,.T."
  ASSERT_LT(face, surface);
  const size_t comma = step.find(',', surface + 3);
  step.replace(surface + 3, comma - surface - 3, "999999");
  ExpectRefused(Load(ModelFormat::kStep, step, "dangling.step"),
                absl::StrCat(id, " ADVANCED_FACE"));

  // IGES: a face (type 510) whose surface pointer names no directory entry.
  std::string iges = Bytes(Solid::kBoxWithHole, ModelFormat::kIges);
  const size_t p = iges.find("\n510,") + 1;
  ASSERT_NE(p, 0u);
  const size_t field = iges.find(',', p) + 1;
  const size_t field_end = iges.find(',', field);
  // The parameter data is free format up to column 64: the longer pointer
  // takes blanks of the padding.
  const std::string pointer = "99999";
  iges.replace(field, field_end - field, pointer);
  iges.erase(iges.find(';', field) + 1, pointer.size() - (field_end - field));
  ExpectRefused(Load(ModelFormat::kIges, iges, "dangling.iges"), " type 510");
}

// An ORIENTED_EDGE whose edge is itself: OpenCASCADE's EdgeStart/EdgeEnd
// recurse until the stack overflows (found by fuzz/step_fuzzer). The fault is
// turned into an error on the load's thread, and the process lives on.
TEST(CadHostile, AnEdgeThatIsItselfOverflowsNoStack) {
  std::string step = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const auto [edge, id] = FindEntity(step, "= ORIENTED_EDGE('',*,*,#");
  ASSERT_NE(edge, std::string::npos);
  const size_t ref = step.find('#', edge);
  step.replace(ref, step.find(',', ref) - ref, id);
  for (int i = 0; i < 2; ++i) {  // twice: the thread's handler set-up survives a fault
    absl::StatusOr<std::shared_ptr<const Model>> model;
    std::thread([&] { model = Load(ModelFormat::kStep, step, "cycle.step"); }).join();
    ASSERT_FALSE(model.ok());
    EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
  }
  EXPECT_TRUE(Load(ModelFormat::kStep, Bytes(Solid::kSphere, ModelFormat::kStep), "after").ok());
}

// 64 random bytes inserted into a part, 40 times: each copy is refused or
// gives the part's 8 faces, every one with an area.
TEST(CadHostile, RandomInsertionsAreRefusedOrHarmless) {
  const std::string& step = Bytes(Solid::kBoxWithHole, ModelFormat::kStep);
  const size_t data = step.find("DATA;") + 5;
  std::mt19937_64 rng(21);
  int refused = 0;
  for (int copy = 0; copy < 40; ++copy) {
    std::string text = step;
    std::string noise(64, ' ');
    for (char& c : noise) c = static_cast<char>(32 + rng() % 95);
    const size_t at = data + rng() % (step.size() - data - 200);
    text.insert(at, noise);
    auto model = Load(ModelFormat::kStep, text, "noisy.step");
    if (!model.ok()) {
      ++refused;
      EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
      EXPECT_LT(model.status().message().size(), 1024u);
      continue;
    }
    EXPECT_EQ((*model)->faces().size(), 8u) << "copy " << copy;
    for (const Face& face : (*model)->faces()) EXPECT_GT(face.area(), 0) << "copy " << copy;
  }
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace sfc::cad
