// Fixture model bytes for the CAD tests, made once per process (the
// kernel's writers are slow-ish).
#ifndef SFCSAMPLER_TESTS_CAD_TEST_UTIL_H_
#define SFCSAMPLER_TESTS_CAD_TEST_UTIL_H_

#include <map>
#include <string>
#include <utility>

#include "cad/fixtures.h"
#include "gtest/gtest.h"

namespace sfc::cad::testing {

inline const std::string& Bytes(fixtures::Solid solid, ModelFormat format) {
  static auto* cache = new std::map<std::pair<fixtures::Solid, ModelFormat>, std::string>;
  auto it = cache->find({solid, format});
  if (it == cache->end()) {
    auto bytes = fixtures::SolidBytes(solid, format);
    EXPECT_TRUE(bytes.ok()) << bytes.status();
    it = cache->emplace(std::make_pair(solid, format), bytes.ok() ? *bytes : "").first;
  }
  return it->second;
}

}  // namespace sfc::cad::testing

#endif  // SFCSAMPLER_TESTS_CAD_TEST_UTIL_H_
