// Conversions into the sfcsampler.v1 wire types of what only a sampler has:
// the catalogue and stored models (a prepared tree goes on the wire as its
// summary, engine/sampling_engine.h SummarizeTree, by proto/convert.h). Used
// by the server; the client library does without them. Pure functions.
#ifndef SFCSAMPLER_PROTO_SERVICE_SERVICE_CONVERT_H_
#define SFCSAMPLER_PROTO_SERVICE_SERVICE_CONVERT_H_

#include "catalog/catalog.h"
#include "engine/model_source.h"
#include "sfcsampler/v1/sampler.pb.h"

namespace sfc {

void ToProto(const CatalogEntry& entry, ::sfcsampler::v1::CatalogEntry* out);
// A stored model; `already`: it was stored before this upload.
void ToProto(const StoredModel& model, bool already, ::sfcsampler::v1::ModelInfo* out);

}  // namespace sfc

#endif  // SFCSAMPLER_PROTO_SERVICE_SERVICE_CONVERT_H_
