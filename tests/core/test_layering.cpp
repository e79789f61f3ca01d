// The house rule of DESIGN.md: a layer includes only itself and the layers below it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>

TEST(Layering, NoLayerIncludesAHigherOne) {
  // Allowed includes per layer (itself, core and everything below it; mirrors
  // src/elastolearn/CMakeLists.txt).
  const std::map<std::string, std::set<std::string>> allowed = {
    { "core", { "core", "config.hpp" } },
    { "mesh", { "core", "mesh", "config.hpp" } },
    { "material", { "core", "material" } },
    { "fem", { "core", "mesh", "material", "fem" } },
    { "sim", { "core", "mesh", "material", "fem", "sim" } },
    { "capture", { "core", "mesh", "capture" } },
    { "observe", { "core", "mesh", "material", "fem", "sim", "capture", "observe" } },
    { "learn", { "core", "mesh", "material", "fem", "sim", "capture", "observe", "learn" } },
    { "springs", { "core", "springs" } },
    { "io",
        { "core", "mesh", "material", "fem", "sim", "capture", "observe", "learn", "springs", "io",
            "config.hpp" } },
  };
  const std::regex include_re(R"(#include\s*<elastolearn/([A-Za-z_.]+))");
  const std::filesystem::path root(ELASTOLEARN_SOURCE_ROOT);
  ASSERT_TRUE(std::filesystem::exists(root)) << root;
  int files = 0;
  for (const auto& [layer, ok] : allowed) {
    if (!std::filesystem::exists(root / layer))
      continue;
    for (const auto& entry : std::filesystem::directory_iterator(root / layer)) {
      std::ifstream in(entry.path());
      std::string line;
      int lineno = 0;
      ++files;
      while (std::getline(in, line)) {
        ++lineno;
        std::smatch m;
        if (std::regex_search(line, m, include_re)) {
          EXPECT_TRUE(ok.count(m[1].str())) << entry.path().string() << ":" << lineno << " (layer "
                                            << layer << ") includes " << m[1].str();
        }
      }
    }
  }
  EXPECT_GT(files, 0);
}
