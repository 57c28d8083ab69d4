// The x-surface-key a client sends with every request, so that a
// consistent-hash proxy (docker/) takes all requests for one tree, or one
// model, to the same replica and its cache. Computed from the request's text
// alone, without the catalogue or any parser:
//  - a request naming an uploaded model (FORMAT:sha256=HEX) routes by the
//    model (ModelRoutingKey), with its FindModel and UploadModel;
//  - any other request routes by the tree key (request/tree_key.h) of its
//    specs as written, whitespace removed. That is the server's own tree key
//    when the specs are written canonically ("torus:R=2;r=0.5"); two
//    spellings of one surface may reach two replicas, each with the same tree.
// The C++ client, the CLI and Python send this same key. Pure function.
#ifndef SFCSAMPLER_REQUEST_ROUTING_KEY_H_
#define SFCSAMPLER_REQUEST_ROUTING_KEY_H_

#include <string>

#include "request/sample_request.h"

namespace sfc {

std::string RoutingKey(const TreeSpec& spec);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_ROUTING_KEY_H_
