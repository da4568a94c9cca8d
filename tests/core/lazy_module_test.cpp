// brdf::LazyModule: where it looks, and the one-line errors when a module is missing, cannot be
// loaded or lacks an entry point. The real module used is the OpenImageIO reader the build
// makes (libbrdf_oiio_reader.so in BRDF_TEST_MODULE_DIR).
#include "brdf/core/lazy_module.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "brdf/core/error.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

class LazyModuleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "brdf_lazy_module_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    const char* old = std::getenv("BRDF_MODULE_DIR");
    had_env_ = old != nullptr;
    if (had_env_) old_env_ = old;
  }
  void TearDown() override {
    if (had_env_)
      ::setenv("BRDF_MODULE_DIR", old_env_.c_str(), 1);
    else
      ::unsetenv("BRDF_MODULE_DIR");
    fs::remove_all(dir_);
  }
  // The message of the IoError `module.Symbol(symbol)` throws ("" when it does not throw).
  static std::string ErrorOf(LazyModule& module, const char* symbol) {
    try {
      module.Symbol(symbol);
    } catch (const IoError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
  bool had_env_ = false;
  std::string old_env_;
};

TEST_F(LazyModuleTest, EnvironmentFolderIsTheOnlyPlaceSearchedWhenSet) {
  ::setenv("BRDF_MODULE_DIR", dir_.c_str(), 1);
  EXPECT_EQ(LazyModule::SearchDirectories(), std::vector<std::string>{dir_.string()});
}

TEST_F(LazyModuleTest, DefaultSearchStartsNextToTheExecutableThenTheBuildTree) {
  ::unsetenv("BRDF_MODULE_DIR");
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  // BRDF_TEST_MODULE_DIR_FROM_EXE is what CMake computed from GNUInstallDirs, e.g.
  // "../lib/brdf-toolchain" for bin/ and lib/.
  const std::string installed =
      (exe.parent_path() / BRDF_TEST_MODULE_DIR_FROM_EXE).lexically_normal().string();
  const std::string build = fs::path(BRDF_TEST_MODULE_DIR).lexically_normal().string();
  EXPECT_EQ(LazyModule::SearchDirectories(), (std::vector<std::string>{installed, build}));
}

TEST_F(LazyModuleTest, MissingModuleGivesOneLineNamingItThePurposeAndTheFolder) {
  ::setenv("BRDF_MODULE_DIR", dir_.c_str(), 1);
  LazyModule module("libbrdf_not_there.so", "testing the loader");
  const std::string message = ErrorOf(module, "anything");
  EXPECT_EQ(message, "testing the loader needs the module libbrdf_not_there.so, which is not in " +
                         dir_.string() +
                         " (reinstall brdf-toolchain, or set BRDF_MODULE_DIR to the folder "
                         "that holds it)");
  EXPECT_FALSE(module.loaded());
  EXPECT_EQ(ErrorOf(module, "anything"), message);  // the same line every time
}

TEST_F(LazyModuleTest, FileThatIsNotALibrarySaysItCannotBeLoaded) {
  ::setenv("BRDF_MODULE_DIR", dir_.c_str(), 1);
  std::ofstream(dir_ / "libbrdf_broken.so") << "not an ELF file\n";
  LazyModule module("libbrdf_broken.so", "testing the loader");
  const std::string message = ErrorOf(module, "anything");
  EXPECT_EQ(message.rfind("testing the loader needs the module libbrdf_broken.so, which cannot "
                          "be loaded: ",
                          0),
            0u)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST_F(LazyModuleTest, RealModuleLoadsOnFirstUseAndReportsAMissingEntryPoint) {
  ::setenv("BRDF_MODULE_DIR", BRDF_TEST_MODULE_DIR, 1);
  LazyModule module("libbrdf_oiio_reader.so", "testing the loader");
  EXPECT_FALSE(module.loaded());  // constructing loads nothing
  EXPECT_NE(module.Symbol("brdf_oiio_read_rgb"), nullptr);
  EXPECT_TRUE(module.loaded());
  const std::string path = (fs::path(BRDF_TEST_MODULE_DIR) / "libbrdf_oiio_reader.so").string();
  EXPECT_EQ(module.loaded_path(), path);
  EXPECT_EQ(ErrorOf(module, "no_such_entry"),
            "testing the loader: the module " + path +
                " has no entry point 'no_such_entry' (reinstall brdf-toolchain)");
  using Abi = const char*();
  EXPECT_EQ(std::string(module.Entry<Abi>("brdf_module_abi")()), BRDF_MODULE_ABI_TAG);
}

TEST_F(LazyModuleTest, ModuleLinkingAProjectLibraryRunsItsCode) {
  ::setenv("BRDF_MODULE_DIR", BRDF_TEST_MODULE_DIR, 1);
  LazyModule module("libbrdf_lazy_module_fixture.so", "testing the loader");
  auto* position = module.Entry<void(unsigned long long, std::string*)>("brdf_test_byte_position");
  std::string text;
  position(1840, &text);
  EXPECT_EQ(text, "byte 1840");  // the spelling error.h documents
}

TEST_F(LazyModuleTest, ModuleOfAnotherBuildIsRefused) {
  // A shared object without brdf_module_abi stands for a module of another build.
  ::setenv("BRDF_MODULE_DIR", dir_.c_str(), 1);
  fs::copy_file(BRDF_TEST_FOREIGN_SO, dir_ / "libbrdf_foreign.so");
  LazyModule module("libbrdf_foreign.so", "testing the loader");
  const std::string message = ErrorOf(module, "anything");
  EXPECT_NE(message.find("belongs to another build ('no build identity', expected '" +
                         std::string(BRDF_MODULE_ABI_TAG) + "'"),
            std::string::npos)
      << message;
}

}  // namespace
}  // namespace brdf
