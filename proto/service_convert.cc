#include "proto/service_convert.h"

#include <string>

#include "core/curve_tree.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

void ToProto(const PreparedTree& t, v1::TreeInfo* out) {
  out->set_key(t.key.Hex());
  out->set_key_with_grade(t.key.HexWithGrade(t.grade));
  out->set_canonical(t.key.canonical);
  out->set_grade(t.grade);
  out->set_cache_hit(t.lookup.cache_hit);
  out->set_refined(t.lookup.refined);
  out->set_kind(std::string(t.kind));
  if (!t.lookup.tree) {  // a mesh's or a model's trees: their size only
    out->set_leaves(t.lookup.any->leaves());
    out->set_bytes(t.lookup.any->bytes());
    return;
  }
  const CurveTree& tree = *t.lookup.tree;
  out->set_leaves(tree.leaf_count());
  out->set_bytes(tree.bytes());
  out->set_min_depth(tree.min_depth());
  out->set_max_depth(tree.max_depth());
  out->set_tolerance(tree.options().tolerance);
  out->set_flatness_capped_leaves(tree.precision().geometry_capped_leaves);
  out->set_mass_capped_leaves(tree.precision().mass_capped_leaves);
  auto add = [](const DepthCapHit& h, v1::DepthCapWarning* w) {
    w->set_test(h.test == DepthCapHit::Test::kGeometry ? "flatness"
                : h.test == DepthCapHit::Test::kMass   ? "mass"
                                                       : "singular");
    w->set_u0(h.u0), w->set_v0(h.v0), w->set_size(h.size);
    w->set_measured(h.measured), w->set_limit(h.limit);
  };
  const PrecisionReport& precision = tree.precision();
  for (const DepthCapHit& h : precision.worst) add(h, out->add_warnings());
  for (const DepthCapHit& h : precision.singular) add(h, out->add_singular());
  out->set_error_samples(precision.error_samples);
  out->set_unresolved_error_samples(precision.unresolved_error_samples);
  out->set_singular_leaves(precision.singular_leaves);
  out->set_warped_leaves(precision.warped_leaves);
  out->set_small_failing_leaves(precision.small_failing_leaves);
}

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
