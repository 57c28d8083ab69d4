#include "kinds/module_kind.h"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "base/echo.h"
#include "base/worker_pool.h"
#include "core/types/sample_batch.h"
#include "request/sample_request.h"

namespace sfc {
namespace {

// The folder of the binary (executable or shared object) holding this code,
// from the dynamic linker's map: a shared object's path as it was loaded, the
// executable's from /proc/self/exe (its map entry has no name). Never a
// path relative to the working directory.
std::optional<std::filesystem::path> OwnFolder() {
  Dl_info info;
  struct link_map* map = nullptr;
  if (dladdr1(reinterpret_cast<void*>(&KindModuleAbi), &info, reinterpret_cast<void**>(&map),
              RTLD_DL_LINKMAP) == 0 ||
      map == nullptr) {
    return std::nullopt;
  }
  std::error_code error;
  const std::filesystem::path path =
      map->l_name && map->l_name[0] ? std::filesystem::path(map->l_name)
                                    : std::filesystem::read_symlink("/proc/self/exe", error);
  if (error || !path.is_absolute()) return std::nullopt;
  const auto real = std::filesystem::canonical(path, error);
  if (error) return std::nullopt;
  return real.parent_path();
}

std::vector<std::filesystem::path> Candidates(const std::string& file) {
  std::vector<std::filesystem::path> out;
  if (const char* dir = std::getenv("SFCSAMPLER_LIB_DIR"); dir && *dir) out.emplace_back(dir);
  if (auto own = OwnFolder()) {
    out.push_back(*own);
    out.push_back(*own / ".." / "lib" / "sfcsampler");
  }
#ifdef SFC_BUILD_MODULE_DIR
  out.emplace_back(SFC_BUILD_MODULE_DIR);
#endif
  std::vector<std::filesystem::path> files;
  for (const auto& dir : out) {
    const auto path = (dir / file).lexically_normal();
    if (std::find(files.begin(), files.end(), path) == files.end()) files.push_back(path);
  }
  return files;
}

class ModuleKind final : public SurfaceKind {
 public:
  ModuleKind(const KindInfo& info, std::string file, std::string factory)
      : info_(info), file_(std::move(file)), factory_(std::move(factory)) {}

  const KindInfo& info() const override { return info_; }

  absl::StatusOr<ResolvedSurface> Resolve(const TreeSpec& spec, const StoredModel* model,
                                          const KindContext& context) const override {
    const SurfaceKind* kind = Loaded();
    if (!kind) return status_;
    return kind->Resolve(spec, model, context);
  }

  absl::StatusOr<std::string> Describe(const StoredModel& model,
                                       const KindContext& context) const override {
    const SurfaceKind* kind = Loaded();
    if (!kind) return status_;
    return kind->Describe(model, context);
  }

 private:
  // The module's kind, loading it on the first call; null (and status_ set)
  // when it cannot be used.
  const SurfaceKind* Loaded() const {
    std::call_once(once_, [this] { status_ = Load(); });
    return kind_.get();
  }

  absl::Status Load() const {
    std::vector<std::string> tried;
    for (const auto& path : Candidates(file_)) {
      std::error_code error;
      if (!std::filesystem::exists(path, error)) {
        tried.push_back(path.string());
        continue;
      }
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        const char* why = dlerror();
        return Refused(path, Echo(why ? why : "dlopen failed", kMaxNameEcho));
      }
      auto abi = reinterpret_cast<const char* (*)()>(dlsym(handle, "sfcsampler_kind_module_abi"));
      auto make = reinterpret_cast<SurfaceKind* (*)(WorkerPool*)>(dlsym(handle, factory_.c_str()));
      if (!abi || !make) return Refused(path, "it lacks the kind module's entry points");
      if (KindModuleAbi() != abi()) {
        return Refused(path, absl::StrCat("it is from another build (", Echo(abi()),
                                          ", this program is ", KindModuleAbi(), ")"));
      }
      kind_.reset(make(&WorkerPool::Shared()));  // one pool for the process
      if (!kind_) return Refused(path, "its factory made no kind");
      return absl::OkStatus();
    }
    return absl::FailedPreconditionError(ClipMessage(
        absl::StrCat(std::string(info_.what), " needs the module ", file_, ", which is not in ",
                     absl::StrJoin(tried, ", "),
                     "; set SFCSAMPLER_LIB_DIR to the folder that holds it"),
        kMaxMessage));
  }

  absl::Status Refused(const std::filesystem::path& path, const std::string& why) const {
    return absl::FailedPreconditionError(
        ClipMessage(absl::StrCat(std::string(info_.what), " needs the module ", path.string(),
                                 ", which cannot be used: ", why),
                    kMaxMessage));
  }

  static constexpr size_t kMaxMessage = 900;

  const KindInfo info_;
  const std::string file_, factory_;
  mutable std::once_flag once_;
  mutable std::unique_ptr<const SurfaceKind> kind_;  // set once, under once_
  mutable absl::Status status_;                      // likewise
};

}  // namespace

std::unique_ptr<const SurfaceKind> MakeModuleKind(const KindInfo& info, std::string file,
                                                  std::string factory) {
  return std::make_unique<ModuleKind>(info, std::move(file), std::move(factory));
}

std::string KindModuleAbi() {
  return absl::StrCat(kAlgorithmVersion, "/", SFC_BUILD_ID, "/", sizeof(TreeSpec), ".",
                      sizeof(KindContext), ".", sizeof(ResolvedSurface), ".", sizeof(CursorSpec),
                      ".", sizeof(KindInfo), ".", sizeof(StoredModel), ".", sizeof(SampleBatch),
                      ".", sizeof(EngineLimits), ".", sizeof(TreeLookup), ".", sizeof(BuildControl),
                      ".", sizeof(TreeSummary), ".", sizeof(WorkerPool));
}

}  // namespace sfc
