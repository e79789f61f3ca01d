#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <unistd.h>

using namespace elastolearn;
namespace fs = std::filesystem;

TEST(AtomicFile, UncommittedWriteLeavesNothing) {
  // Per process: another build's tests may run at the same time.
  const fs::path dir
      = fs::temp_directory_path() / ("elastolearn_atomic_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path target = dir / "out.txt";
  {
    AtomicFile f(target);
    std::ofstream(f.temp_path()) << "partial";
    EXPECT_TRUE(fs::exists(f.temp_path()));
  } // destroyed without commit, e.g. by an exception
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir));
  write_text_file_atomic(target, "complete");
  EXPECT_EQ(read_text_file(target), "complete");
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingFileIsAnInputErrorNamingThePath) {
  try {
    read_text_file("/nonexistent/dir/file.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/file.json"), std::string::npos);
  }
}
