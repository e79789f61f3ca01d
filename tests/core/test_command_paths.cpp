// check_command_paths: a command's output may never be one of its inputs (however spelled or
// linked), two outputs never the same file, and an output that cannot be created is refused
// before any work — all with one InputError naming the output.
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

using namespace elastolearn;
namespace fs = std::filesystem;

namespace {

class CommandPaths : public ::testing::Test {
  protected:
  void SetUp() override {
    m_dir = fs::temp_directory_path()
        / ("elastolearn_command_paths_"
            + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_"
            + std::to_string(::getpid()));
    fs::remove_all(m_dir);
    fs::create_directories(m_dir / "sub");
    std::ofstream(m_dir / "in.h5") << "input";
    std::ofstream(m_dir / "other.h5") << "other";
    m_cwd = fs::current_path();
    fs::current_path(m_dir); // relative spellings below are relative to the test folder
  }
  void TearDown() override {
    fs::current_path(m_cwd);
    fs::remove_all(m_dir);
  }
  /// The InputError message of check_command_paths, or "" if it passed.
  static std::string refusal(
      const std::vector<CommandInput>& inputs, const std::vector<CommandOutput>& outputs) {
    try {
      check_command_paths(inputs, outputs);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path m_dir, m_cwd;
};

TEST_F(CommandPaths, SameFileSeesThroughSpellingsAndLinks) {
  fs::create_symlink("in.h5", "link.h5");
  fs::create_hard_link("in.h5", "hard.h5");
  EXPECT_TRUE(same_file("in.h5", "./in.h5"));
  EXPECT_TRUE(same_file("in.h5", "sub/../in.h5"));
  EXPECT_TRUE(same_file("in.h5", m_dir / "in.h5"));
  EXPECT_TRUE(same_file("in.h5", "link.h5"));
  EXPECT_TRUE(same_file("in.h5", "hard.h5"));
  EXPECT_FALSE(same_file("in.h5", "other.h5"));
  // Neither exists: compared as normalised absolute paths.
  EXPECT_TRUE(same_file("new.h5", "./sub/../new.h5"));
  EXPECT_TRUE(same_file("sub/out", "sub/out/"));
  EXPECT_FALSE(same_file("new.h5", "new2.h5"));
  // Only one exists: different files.
  EXPECT_FALSE(same_file("in.h5", "new.h5"));
}

TEST_F(CommandPaths, RefusesAnOutputThatIsAnInputNamingBoth) {
  const std::string message
      = refusal({ { "in.h5", "trajectory" } }, { { "./in.h5", "observation output (-o)" } });
  EXPECT_EQ(message.rfind("./in.h5: ", 0), 0u) << message;
  EXPECT_NE(
      message.find("observation output (-o) is the trajectory (given as in.h5)"), std::string::npos)
      << message;
  EXPECT_NE(message.find("would replace the input"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  // A folder output that is an input file is refused the same way.
  EXPECT_NE(refusal({ { "in.h5", "scene" } }, { { "in.h5", "--vtu folder", OutputKind::folder } })
                .find("would replace the input"),
      std::string::npos);
  std::ifstream in("in.h5");
  std::string contents;
  in >> contents;
  EXPECT_EQ(contents, "input"); // the check itself never touches a file
}

TEST_F(CommandPaths, RefusesTwoOutputsThatAreOneFile) {
  const std::string message
      = refusal({}, { { "out.json", "output (-o)" }, { "./out.json", "checkpoint" } });
  EXPECT_NE(message.find("the checkpoint and the output (-o) are the same file"), std::string::npos)
      << message;
}

TEST_F(CommandPaths, RefusesOutputsThatCannotBeCreated) {
  EXPECT_NE(
      refusal({}, { { "in.h5/x.h5", "output" } }).find("in.h5 is not a folder"), std::string::npos);
  EXPECT_NE(refusal({}, { { "in.h5/a/b/x.h5", "output" } }).find("in.h5 is not a folder"),
      std::string::npos);
  EXPECT_NE(refusal({}, { { "sub", "output" } }).find("is a folder"), std::string::npos);
  EXPECT_NE(refusal({}, { { "in.h5", "report folder", OutputKind::folder } }).find("not a folder"),
      std::string::npos);
  EXPECT_NE(
      refusal({}, { { "", "output (-o)" } }).find("output (-o): empty path"), std::string::npos);
}

TEST_F(CommandPaths, AcceptsDistinctCreatableOutputsAndCreatesNothing) {
  std::ofstream("old.h5") << "an earlier output";
  EXPECT_EQ(refusal({ { "in.h5", "trajectory" }, { "other.h5", "list" } },
                { { "out.h5", "output" }, { "sub/new/deeper/x.h5", "second output" },
                    { "sub/vtu", "ParaView folder", OutputKind::folder },
                    { "sub", "existing folder", OutputKind::folder },
                    { "old.h5", "overwritten output" } }),
      "");
  EXPECT_FALSE(fs::exists("sub/new"));
  EXPECT_FALSE(fs::exists("sub/vtu"));
  EXPECT_FALSE(fs::exists("out.h5"));
}

TEST(PrintableLine, EscapesControlBytesAndBrokenUtf8AndCutsLongText) {
  EXPECT_EQ(printable_line("plain ≥ Σ text"), "plain ≥ Σ text"); // valid UTF-8 stays
  EXPECT_EQ(printable_line("a\nb\r\x1b[31m"), "a\\x0ab\\x0d\\x1b[31m");
  EXPECT_EQ(printable_line("bad \xff\xc3 end"), "bad \\xff\\xc3 end");
  const std::string cut = printable_line(std::string(1000, 'x'), 50);
  EXPECT_EQ(cut, std::string(50, 'x') + "...");
}

} // namespace
