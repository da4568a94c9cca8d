#include "brdf/core/lazy_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "brdf/core/error.h"

#ifndef BRDF_MODULE_DIR_FROM_EXE
#error "BRDF_MODULE_DIR_FROM_EXE must be defined by the build (processing/CMakeLists.txt)"
#endif
#ifndef BRDF_BUILD_MODULE_DIR
#error "BRDF_BUILD_MODULE_DIR must be defined by the build (processing/CMakeLists.txt)"
#endif

namespace brdf {

namespace fs = std::filesystem;

struct LazyModule::State {
  std::string file_name, needed_for;
  std::once_flag once;
  void* handle = nullptr;
  std::string path;   // where it was loaded from
  std::string error;  // why loading failed (kept: every later call reports the same line)
};

namespace {

std::string JoinDirectories(const std::vector<std::string>& dirs) {
  std::string out;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    if (i > 0) out += i + 1 == dirs.size() ? " or " : ", ";
    out += dirs[i];
  }
  return out;
}

}  // namespace

LazyModule::LazyModule(std::string file_name, std::string needed_for)
    : state_(std::make_unique<State>()) {
  state_->file_name = std::move(file_name);
  state_->needed_for = std::move(needed_for);
}

// The handle is deliberately never dlclose()d: static objects of the module (OpenImageIO's
// plugin registry, Ceres's loggers) may outlive any one caller.
LazyModule::~LazyModule() = default;

std::vector<std::string> LazyModule::SearchDirectories() {
  if (const char* env = std::getenv("BRDF_MODULE_DIR"); env != nullptr && *env != '\0')
    return {env};
  std::vector<std::string> dirs;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back((exe.parent_path() / BRDF_MODULE_DIR_FROM_EXE).lexically_normal());
  const std::string build_dir = fs::path(BRDF_BUILD_MODULE_DIR).lexically_normal();
  if (dirs.empty() || dirs.front() != build_dir) dirs.push_back(build_dir);
  return dirs;
}

void* LazyModule::Symbol(const char* symbol) {
  State& s = *state_;
  std::call_once(s.once, [&s] {
    const std::vector<std::string> dirs = SearchDirectories();
    const std::string what = s.needed_for + " needs the module " + s.file_name;
    for (const std::string& dir : dirs) {
      const fs::path candidate = fs::path(dir) / s.file_name;
      std::error_code ec;
      if (!fs::is_regular_file(candidate, ec)) continue;
      // RTLD_LOCAL: the module's libraries do not leak their symbols into the program.
      void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (handle == nullptr) {
        const char* why = ::dlerror();
        s.error = what + ", which cannot be loaded: " + (why ? why : "unknown dlopen error") +
                  " (install the missing library with tools/install-deps.sh)";
        return;
      }
      using AbiFunction = const char*();
      auto* abi = reinterpret_cast<AbiFunction*>(::dlsym(handle, "brdf_module_abi"));
      const std::string tag = abi != nullptr ? abi() : "no build identity";
      if (tag != BRDF_MODULE_ABI_TAG) {
        s.error = what + ", but " + candidate.string() + " belongs to another build ('" + tag +
                  "', expected '" BRDF_MODULE_ABI_TAG "'; reinstall brdf-toolchain)";
        ::dlclose(handle);
        return;
      }
      s.handle = handle;
      s.path = candidate.string();
      return;
    }
    s.error = what + ", which is not in " + JoinDirectories(dirs) +
              " (reinstall brdf-toolchain, or set BRDF_MODULE_DIR to the folder that holds it)";
  });
  if (s.handle == nullptr) throw IoError(s.error);
  ::dlerror();  // clear a stale error so the one below belongs to this lookup
  void* address = ::dlsym(s.handle, symbol);
  if (address == nullptr)
    throw IoError(s.needed_for + ": the module " + s.path + " has no entry point '" + symbol +
                  "' (reinstall brdf-toolchain)");
  return address;
}

bool LazyModule::loaded() const { return state_->handle != nullptr; }

std::string LazyModule::loaded_path() const { return state_->path; }

}  // namespace brdf
