// sfcsampler._client: the C++ client library (client/sampler_client.h) in
// Python, for sfcsampler.Client (python/sfcsampler/client.py), which wraps
// it. An extension of its own, loaded with the first Client, so that
// `import sfcsampler` and the embedded sampler load no gRPC.
//
// A Stream runs SamplerClient::Sample on a thread of its own and hands its
// batches over through a queue of at most kQueued; next() waits for one with
// the GIL released and gives its columns to NumPy without a copy (each
// message's columns are copied once, out of the message, by the client
// library). The request comes parsed (sfcsampler._core.Request, a type
// the _core extension registers; pybind11 shares it between the two).
//
// Thread-safety: a Client may be used from several Python threads at once
// (SamplerClient is thread-safe); a Stream belongs to one thread.
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "client/sample_writer.h"
#include "client/sampler_client.h"
#include "google/protobuf/descriptor.h"
#include "google/protobuf/message.h"
#include "pybind11/pybind11.h"
#include "pybind11/stl.h"
#include "python/bindings/batch_columns.h"
#include "python/bindings/errors.h"
#include "python/bindings/register.h"
#include "python/bindings/request.h"
#include "python/bindings/tree_summary_dict.h"
#include "request/model_spec.h"
#include "request/stream_options.h"
#include "request/tree_count.h"

namespace py = pybind11;

namespace sfc::python {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

py::dict MessageDict(const Message& message);

// One value of a field (`i` < 0: a singular field, else the repeated
// field's i-th), as protobuf's own Python classes give it: enums as numbers.
py::object FieldValue(const Message& m, const FieldDescriptor* f, int i) {
  const auto* r = m.GetReflection();
  const bool one = i < 0;
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      return py::int_(one ? r->GetInt32(m, f) : r->GetRepeatedInt32(m, f, i));
    case FieldDescriptor::CPPTYPE_INT64:
      return py::int_(one ? r->GetInt64(m, f) : r->GetRepeatedInt64(m, f, i));
    case FieldDescriptor::CPPTYPE_UINT32:
      return py::int_(one ? r->GetUInt32(m, f) : r->GetRepeatedUInt32(m, f, i));
    case FieldDescriptor::CPPTYPE_UINT64:
      return py::int_(one ? r->GetUInt64(m, f) : r->GetRepeatedUInt64(m, f, i));
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return py::float_(one ? r->GetDouble(m, f) : r->GetRepeatedDouble(m, f, i));
    case FieldDescriptor::CPPTYPE_FLOAT:
      return py::float_(one ? r->GetFloat(m, f) : r->GetRepeatedFloat(m, f, i));
    case FieldDescriptor::CPPTYPE_BOOL:
      return py::bool_(one ? r->GetBool(m, f) : r->GetRepeatedBool(m, f, i));
    case FieldDescriptor::CPPTYPE_ENUM:
      return py::int_(one ? r->GetEnumValue(m, f) : r->GetRepeatedEnumValue(m, f, i));
    case FieldDescriptor::CPPTYPE_STRING: {
      const std::string s = one ? r->GetString(m, f) : r->GetRepeatedString(m, f, i);
      if (f->type() == FieldDescriptor::TYPE_BYTES) return py::bytes(s);
      return py::str(s);
    }
    case FieldDescriptor::CPPTYPE_MESSAGE:
      return MessageDict(one ? r->GetMessage(m, f) : r->GetRepeatedMessage(m, f, i));
  }
  return py::none();
}

// A message as a dict of every field by its proto name, in declaration order
// (repeated fields as lists, messages as dicts): what ListCatalog and
// GetCacheStats give Python.
py::dict MessageDict(const Message& message) {
  py::dict out;
  const auto* descriptor = message.GetDescriptor();
  for (int k = 0; k < descriptor->field_count(); ++k) {
    const FieldDescriptor* f = descriptor->field(k);
    if (f->is_repeated()) {
      py::list values;
      const int n = message.GetReflection()->FieldSize(message, f);
      for (int i = 0; i < n; ++i) values.append(FieldValue(message, f, i));
      out[py::str(f->name())] = values;
    } else {
      out[py::str(f->name())] = FieldValue(message, f, -1);
    }
  }
  return out;
}

template <typename T>
T ValueOrThrow(absl::StatusOr<T> value) {
  ThrowIfError(value.status());
  return *std::move(value);
}

// One Sample call's batches, pulled by Python: the call runs on a thread of
// its own and waits while kQueued batches are waiting to be read.
class PyStream {
 public:
  static constexpr size_t kQueued = 2;

  PyStream(std::shared_ptr<SamplerClient> client, SampleRequest request, StreamOptions stream)
      : fields_(request.fields), float32_(stream.precision == ColumnPrecision::kFloat32) {
    thread_ = std::thread([this, client = std::move(client), request = std::move(request), stream] {
      Run(*client, request, stream);
    });
  }

  ~PyStream() { Close(); }

  // The next batch's columns as a dict of arrays; StopIteration at the end;
  // the call's error as its sfcsampler.Error.
  py::dict Next() {
    std::optional<BatchColumns> item;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mu_);
      // Wake now and then for Ctrl-C: the server may take long (a tree build).
      while (!cv_.wait_for(lock, std::chrono::milliseconds(100),
                           [&] { return !queue_.empty() || finished_; })) {
        lock.unlock();
        {
          py::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        }
        lock.lock();
      }
      if (!queue_.empty()) {
        item = std::move(queue_.front());
        queue_.pop_front();
        cv_.notify_all();
      }
    }
    if (!item) {
      ThrowIfError(result_.status());
      throw py::stop_iteration();
    }
    return ColumnsDict(*std::move(item), fields_);
  }

  // Stops the call if it still runs (the caller stopped reading) and waits
  // for its thread; the call stops at its next message at the latest.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      closed_ = true;
      cv_.notify_all();
    }
    if (thread_.joinable()) {
      py::gil_scoped_release release;
      thread_.join();
    }
  }

  // The stream's header, once a batch has been read or the stream ended
  // (None before): its tree summary and the set it serves.
  py::object Header() {
    std::lock_guard<std::mutex> lock(mu_);
    if (!info_) return py::none();
    py::dict d;
    d["tree"] = TreeSummaryDict(info_->tree);
    d["algorithm_version"] = info_->algorithm_version;
    d["seed"] = info_->seed;
    d["begin"] = info_->begin;
    d["end"] = info_->end;
    d["expected_samples"] = info_->expected_samples;
    return d;
  }
  // Of a finished call: its resumes and the bytes of its messages (0 before).
  int resumes() {
    std::lock_guard<std::mutex> lock(mu_);
    return result_.ok() ? result_->resumes : 0;
  }
  uint64_t wire_bytes() {
    std::lock_guard<std::mutex> lock(mu_);
    return result_.ok() ? result_->wire_bytes : 0;
  }

 private:
  void Run(SamplerClient& client, const SampleRequest& request, const StreamOptions& stream) {
    auto result = client.Sample(request, stream, [&](const StreamInfo& info, SampleBatch& batch) {
      BatchColumns item;
      item.batch = std::move(batch);  // the client refills `batch` from the next message
      if (float32_) Narrow(&item);
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [&] { return queue_.size() < kQueued || closed_; });
      if (closed_) return absl::CancelledError("the stream was closed before its end");
      if (!info_) info_ = info;
      queue_.push_back(std::move(item));
      cv_.notify_all();
      return absl::OkStatus();
    });
    std::lock_guard<std::mutex> lock(mu_);
    if (result.ok() && !info_) info_ = result->header;  // a stream without samples
    result_ = std::move(result);
    finished_ = true;
    cv_.notify_all();
  }

  const SampleFields fields_;
  const bool float32_;
  std::thread thread_;

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<BatchColumns> queue_;                                        // guarded by mu_
  std::optional<StreamInfo> info_;                                        // guarded by mu_
  absl::StatusOr<StreamSummary> result_ = absl::UnknownError("running");  // guarded by mu_
  bool finished_ = false;                                                 // guarded by mu_
  bool closed_ = false;                                                   // guarded by mu_
};

class PyClient {
 public:
  PyClient(const std::string& target, const std::string& token, bool tls,
           const std::string& tls_roots, double timeout, const std::string& precision,
           uint32_t batch_size, int max_resumes, double resume_backoff,
           const std::string& encoding) {
    ClientOptions o;
    o.target = target;
    o.token = token;
    o.tls = tls || !tls_roots.empty();
    o.tls_root_certs_file = tls_roots;
    o.deadline_seconds = timeout;
    o.stream.precision = ValueOrThrow(ParseColumnPrecision(precision));
    o.stream.batch_size = batch_size;
    o.stream.encoding = ValueOrThrow(ParseColumnEncoding(encoding));
    o.max_resumes = max_resumes;
    o.resume_backoff_seconds = resume_backoff;
    stream_ = o.stream;
    py::gil_scoped_release release;
    client_ = ValueOrThrow(SamplerClient::Connect(o));
  }

  void Close() { client_.reset(); }

  // `precision` "" and `batch_size` 0: the client's. `columns` as
  // SampleWriter::SourceFields takes them (empty: every column the request
  // makes); the others are not sent.
  std::unique_ptr<PyStream> Stream(const PyRequest& r, const std::string& precision,
                                   uint32_t batch_size, const std::vector<std::string>& columns) {
    StreamOptions stream = stream_;
    if (!precision.empty()) stream.precision = ValueOrThrow(ParseColumnPrecision(precision));
    if (batch_size != 0) stream.batch_size = batch_size;
    SampleRequest request = r.request;
    request.fields = SampleWriter::SourceFields(request.fields, columns);
    return std::make_unique<PyStream>(Connected(), std::move(request), stream);
  }

  py::dict Prepare(const PyRequest& r) {
    const std::shared_ptr<SamplerClient> client = Connected();
    absl::StatusOr<PreparedSummary> prepared;
    {
      py::gil_scoped_release release;
      const absl::StatusOr<uint64_t> count = ResolveTreeCount(r.request);
      prepared = count.ok() ? client->Prepare(r.request.tree, *count)
                            : absl::StatusOr<PreparedSummary>(count.status());
    }
    return TreeSummaryDict(ValueOrThrow(std::move(prepared)).tree);
  }

  std::string Upload(const std::string& spec) {
    const std::shared_ptr<SamplerClient> client = Connected();
    py::gil_scoped_release release;
    return ValueOrThrow(client->EnsureModel(spec));
  }

  std::string UploadBytes(const std::string& format, const py::bytes& data,
                          const std::string& name) {
    const std::optional<ModelFormat> parsed = ModelFormatFromName(format);
    if (!parsed) {
      throw StatusException(absl::InvalidArgumentError("model format must be " + ModelFormatList() +
                                                       ", not \"" + format + "\""));
    }
    std::string bytes = data;
    const std::shared_ptr<SamplerClient> client = Connected();
    py::gil_scoped_release release;
    return ValueOrThrow(client->EnsureModelBytes(*parsed, name, std::move(bytes)));
  }

  bool Health(const std::string& service, double timeout) {
    const std::shared_ptr<SamplerClient> client = Connected();
    py::gil_scoped_release release;
    return ValueOrThrow(client->CheckHealth(service, timeout));
  }

  py::dict CacheStats() {
    const std::shared_ptr<SamplerClient> client = Connected();
    absl::StatusOr<::sfcsampler::v1::CacheStats> stats;
    {
      py::gil_scoped_release release;
      stats = client->GetCacheStats();
    }
    return MessageDict(ValueOrThrow(std::move(stats)));
  }

  py::dict Catalog() {
    const std::shared_ptr<SamplerClient> client = Connected();
    absl::StatusOr<::sfcsampler::v1::ListCatalogResponse> catalog;
    {
      py::gil_scoped_release release;
      catalog = client->ListCatalog();
    }
    return MessageDict(ValueOrThrow(std::move(catalog)));
  }

 private:
  std::shared_ptr<SamplerClient> Connected() const {
    if (!client_) {
      throw StatusException(absl::FailedPreconditionError("the Client is closed"));
    }
    return client_;
  }

  StreamOptions stream_;
  std::shared_ptr<SamplerClient> client_;  // null once closed; streams share it
};

}  // namespace
}  // namespace sfc::python

PYBIND11_MODULE(_client, m) {
  using sfc::python::PyClient;
  using sfc::python::PyStream;
  m.doc() = "sfcsampler's C++ client (use sfcsampler.Client, not this module)";
  sfc::python::RegisterErrors(m);
  // The _core extension registers the Request type Stream and Prepare take.
  py::module_::import("sfcsampler._core");

  py::class_<PyStream>(m, "Stream", "One Sample call's batches, in curve order.")
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", &PyStream::Next,
           "The next batch as a dict of NumPy arrays (index, u, v, x, y, z and the requested "
           "columns); the GIL is released while it waits.")
      .def("close", &PyStream::Close, "Stops the call if it still runs.")
      .def_property_readonly("header", &PyStream::Header,
                             "the stream header as a dict (tree, algorithm_version, seed, begin, "
                             "end, expected_samples) once known, else None")
      .def_property_readonly("resumes", &PyStream::resumes)
      .def_property_readonly("wire_bytes", &PyStream::wire_bytes);

  py::class_<PyClient>(m, "Client", "A connection to an sfcsampler-server (SamplerClient).")
      .def(py::init<const std::string&, const std::string&, bool, const std::string&, double,
                    const std::string&, uint32_t, int, double, const std::string&>(),
           py::arg("target"), py::kw_only(), py::arg("token") = "", py::arg("tls") = false,
           py::arg("tls_roots") = "", py::arg("timeout") = 0.0, py::arg("precision") = "float64",
           py::arg("batch_size") = 0, py::arg("max_resumes") = 5, py::arg("resume_backoff") = 0.2,
           py::arg("encoding") = "raw")
      .def("close", &PyClient::Close)
      .def("stream", &PyClient::Stream, py::arg("request"), py::kw_only(),
           py::arg("precision") = "", py::arg("batch_size") = 0,
           py::arg("columns") = std::vector<std::string>())
      .def("prepare", &PyClient::Prepare, py::arg("request"))
      .def("upload", &PyClient::Upload, py::arg("spec"))
      .def("upload_bytes", &PyClient::UploadBytes, py::arg("format"), py::arg("data"),
           py::arg("name") = "")
      .def("health", &PyClient::Health, py::arg("service") = "", py::arg("timeout") = 0.0)
      .def("cache_stats", &PyClient::CacheStats)
      .def("catalog", &PyClient::Catalog);
}
