#include "client/cli/server_sample_source.h"

#include <fstream>
#include <iterator>

#include "absl/strings/ascii.h"
#include "absl/strings/str_format.h"
#include "base/status_macros.h"
#include "engine/model_source.h"
#include "proto/convert.h"

namespace sfc {
namespace {

namespace v1 = ::sfcsampler::v1;

// The bearer token in `path`, without trailing white space.
absl::StatusOr<std::string> ReadToken(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError("cannot read --token-file " + path);
  const std::string token((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return std::string(absl::StripTrailingAsciiWhitespace(token));
}

// The report of a tree the server describes, without a time.
TreeReport Report(const v1::TreeInfo& tree) {
  TreeReport report;
  report.tree = FromProto(tree);
  return report;
}

}  // namespace

ServerSampleSource::ServerSampleSource(const ConnectionFlags& connection,
                                       const SampleSourceOptions& options)
    : connection_(connection), options_(options) {}

absl::StatusOr<SamplerClient*> ServerSampleSource::Client() {
  std::lock_guard<std::mutex> lock(mu_);
  if (client_) return client_.get();
  const ConnectionFlags& c = connection_;
  ClientOptions options;
  options.precision = options_.precision == OutputPrecision::kFloat32 ? v1::PRECISION_FLOAT32
                                                                      : v1::PRECISION_FLOAT64;
  options.target = c.server;
  options.tls = c.tls || !c.tls_roots.empty() || !c.tls_cert.empty();
  options.tls_root_certs_file = c.tls_roots;
  options.tls_cert_file = c.tls_cert;
  options.tls_key_file = c.tls_key;
  options.batch_size = static_cast<uint32_t>(options_.batch_size);
  if (!c.token_file.empty()) {
    ASSIGN_OR_RETURN(options.token, ReadToken(c.token_file));
  }
  ASSIGN_OR_RETURN(client_, SamplerClient::Connect(options));
  return client_.get();
}

absl::Status ServerSampleSource::Connect() { return Client().status(); }

absl::StatusOr<TreeReport> ServerSampleSource::Prepare(const TreeSpec& spec, uint64_t count,
                                                       Progress* progress) {
  ASSIGN_OR_RETURN(SamplerClient * client, Client());
  progress->StartPhase("waiting for " + connection_.server + " to prepare the curve tree");
  auto response = client->Prepare(spec, count);
  progress->EndPhase();
  RETURN_IF_ERROR(response.status());
  TreeReport report = Report(response->tree());
  report.seconds = response->seconds();
  report.seconds_from_server = true;
  return report;
}

absl::StatusOr<std::string> ServerSampleSource::Sample(const SampleRequest& request,
                                                       Progress* progress,
                                                       const TreeCallback& on_tree,
                                                       const BatchCallback& on_batch) {
  ASSIGN_OR_RETURN(SamplerClient * client, Client());
  uint64_t done = 0;
  progress->StartPhase("waiting for " + connection_.server +
                       " (it may be building the curve tree)");
  ASSIGN_OR_RETURN(
      const StreamSummary summary,
      client->Sample(request, [&](const v1::StreamHeader& header, const SampleBatch& batch) {
        if (done == 0) {
          progress->EndPhase();
          if (on_tree) on_tree(Report(header.tree()));
        }
        std::optional<uint64_t> expected;
        if (header.expected_samples() >= 0) expected = header.expected_samples();
        done += batch.size();
        progress->Samples(done, expected.value_or(0));
        return on_batch(expected, batch);
      }));
  progress->Done();
  return absl::StrFormat("from %s (%s, seed %d, %d resumes)", connection_.server,
                         summary.header.algorithm_version(), request.seed, summary.resumes);
}

absl::StatusOr<std::string> ServerSampleSource::CacheStats() {
  ASSIGN_OR_RETURN(SamplerClient * client, Client());
  ASSIGN_OR_RETURN(const v1::CacheStats stats, client->GetCacheStats());
  return stats.DebugString();
}

absl::StatusOr<bool> ServerSampleSource::Serving() {
  ASSIGN_OR_RETURN(SamplerClient * client, Client());
  return client->CheckHealth();
}

absl::StatusOr<std::string> ServerSampleSource::UploadModel(const std::string& spec) {
  ASSIGN_OR_RETURN(SamplerClient * client, Client());
  ASSIGN_OR_RETURN(const auto parsed, ParseModelSpec(spec));
  if (!parsed.has_value()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "\"%s\" names no model file; write FORMAT:FILE with FORMAT step, iges, nurbs, obj or ply",
        spec));
  }
  return client->EnsureModel(spec);
}

absl::StatusOr<std::string> ServerSampleSource::DescribeModel(const std::string&) {
  return absl::FailedPreconditionError(
      "inspect reads model files on this machine; run it without --server");
}

absl::StatusOr<PreparedTree> ServerSampleSource::LocalTree(const SampleRequest&) {
  // The wire carries samples, not trees.
  return absl::FailedPreconditionError(
      "--what curve and param-curve draw the curve tree, which stays on the server; run them "
      "without --server (the tree is the same), or draw samples");
}

}  // namespace sfc
