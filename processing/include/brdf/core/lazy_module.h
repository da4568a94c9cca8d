// A shared library that is loaded the first time one of its entry points is needed.
//
// Why: every library an executable links is mapped and relocated before main() runs, whether
// the command uses it or not. OpenImageIO alone drags in about 260 libraries (0.25–0.5 s and
// 130 MB for `brdf --version`, docs/benchmarks.md "Start-up cost"). Code that needs such a
// dependency is therefore built as a MODULE library (cmake/LazyModule.cmake,
// brdf_add_lazy_module) and reached through a LazyModule: commands that never call it never map
// it.
//
// A module exports plain `extern "C"` functions (BRDF_MODULE_ENTRY) and identifies the build it
// belongs to (BRDF_DEFINE_MODULE_ABI). Its entry points may take C++ types by pointer (the
// module is built by the same compiler, against the same headers and libstdc++), but they must
// not let an exception escape: catch inside, report through an out parameter, and let the
// caller throw the brdf::Error.
//
// Where modules are looked for, first match wins:
//   1. $BRDF_MODULE_DIR, when set and not empty (then nowhere else; for tests and packagers);
//   2. <folder of the running executable>/<BRDF_MODULE_DIR_FROM_EXE>, the installed layout
//      (bin/brdf and lib/brdf-toolchain/*.so: "../lib/brdf-toolchain");
//   3. the build tree's module folder (<build>/lib/brdf-toolchain), so executables and tests
//      run from the build tree without installing.
// A module that is missing, cannot be loaded or comes from another build gives one IoError line
// naming the module, what it is needed for, the folders searched and what to do.
//
// Thread-safe: the first Symbol() call loads the module once; later calls only look up.
// The module stays loaded until the process ends (objects it created may still be alive).
#pragma once

#include <memory>
#include <string>
#include <vector>

// Marks a function a module exports to its LazyModule.
#define BRDF_MODULE_ENTRY extern "C" __attribute__((visibility("default")))

// The build identity a module and its loader must share: project version and compiler.
// BRDF_VERSION_STRING is defined for every target by the project's CMake.
#define BRDF_MODULE_ABI_TAG BRDF_VERSION_STRING " built by " __VERSION__

// Put once in every module's sources (at namespace scope).
#define BRDF_DEFINE_MODULE_ABI() \
  BRDF_MODULE_ENTRY const char* brdf_module_abi() { return BRDF_MODULE_ABI_TAG; }

namespace brdf {

class LazyModule {
 public:
  // `file_name`: the module's file ("libbrdf_oiio_reader.so"). `needed_for`: what the user was
  // doing, for the error message ("reading images through OpenImageIO"). Loads nothing yet.
  LazyModule(std::string file_name, std::string needed_for);
  ~LazyModule();
  LazyModule(const LazyModule&) = delete;
  LazyModule& operator=(const LazyModule&) = delete;

  // Loads the module on first use and returns the address of the exported `symbol`.
  // Throws IoError (one line) when the module is missing, fails to load (e.g. one of its own
  // libraries is not installed), comes from another build, or lacks `symbol`.
  void* Symbol(const char* symbol);

  // Symbol() cast to the entry point's function type, e.g.
  //   auto* read = module.Entry<bool(const char*, RgbImage*, std::string*)>("brdf_read_rgb");
  template <typename Function>
  Function* Entry(const char* symbol) {
    return reinterpret_cast<Function*>(Symbol(symbol));
  }

  // Whether the module has been loaded in this process, and from where ("" before).
  bool loaded() const;
  std::string loaded_path() const;

  // The folders searched, in order (see the header comment).
  static std::vector<std::string> SearchDirectories();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace brdf
