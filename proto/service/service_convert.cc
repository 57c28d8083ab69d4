#include "proto/service/service_convert.h"

#include <string>

namespace sfc {

namespace v1 = ::sfcsampler::v1;

void ToProto(const CatalogEntry& e, v1::CatalogEntry* out) {
  out->set_name(e.name);
  out->set_formula(e.formula);
  out->set_description(e.description);
  for (const CatalogParameter& p : e.parameters) {
    auto* q = out->add_parameters();
    q->set_name(p.name), q->set_default_value(p.default_value), q->set_meaning(p.meaning);
  }
}

void ToProto(const StoredModel& model, bool already, v1::ModelInfo* out) {
  out->set_sha256(model.sha256);
  out->set_format(std::string(ModelFormatName(model.format)));
  out->set_bytes(model.bytes->size());
  out->set_already_stored(already);
  out->set_spec(model.Spec());
}

}  // namespace sfc
