#include "server/sampler_service.h"

#include "catalog/catalog.h"
#include "proto/service/service_convert.h"

namespace sfc {

namespace v1 = ::sfcsampler::v1;

grpc::Status SamplerService::ListCatalog(grpc::ServerContext* context,
                                         const v1::ListCatalogRequest*,
                                         v1::ListCatalogResponse* response) {
  grpc::Status status = Admit(*context);
  if (status.ok()) {
    for (const CatalogEntry& e : SurfaceCatalog()) ToProto(e, response->add_surfaces());
    for (const CatalogEntry& e : DensityCatalog()) ToProto(e, response->add_densities());
    response->set_algorithm_version(kAlgorithmVersion);
  }
  metrics_->CountRequest("ListCatalog", status.error_code());
  return status;
}

}  // namespace sfc
