#include "request/routing_key.h"

#include <algorithm>
#include <cctype>

#include "request/model_spec.h"
#include "request/tree_key.h"

namespace sfc {
namespace {

std::string WithoutWhitespace(std::string text) {
  text.erase(std::remove_if(text.begin(), text.end(),
                            [](unsigned char c) { return std::isspace(c) != 0; }),
             text.end());
  return text;
}

}  // namespace

std::string RoutingKey(const TreeSpec& spec) {
  if (auto model = ParseModelSpec(spec.surface);
      model.ok() && model->has_value() && !(*model)->sha256.empty()) {
    return ModelRoutingKey((*model)->format, (*model)->sha256);
  }
  return MakeTreeKey(WithoutWhitespace(spec.surface), WithoutWhitespace(spec.density), spec.options)
      .Hex();
}

}  // namespace sfc
