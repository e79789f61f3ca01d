#pragma once
// Helpers shared by the io tests: scratch directories and InputError expectations.
#include <elastolearn/core/error.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

namespace elastolearn::io::test {

/// A fresh, empty directory for the current test, removed afterwards.
class ScratchDir {
  public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_path = std::filesystem::temp_directory_path()
        / ("elastolearn_io_" + std::string(info->test_suite_name()) + "_" + info->name() + "_"
            + std::to_string(::getpid()));
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
  }
  const std::filesystem::path& path() const { return m_path; }
  std::filesystem::path operator/(const std::string& name) const { return m_path / name; }
  /// Names of the files in the directory (to check that no temporary file was left behind).
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(m_path)) {
      names.push_back(e.path().filename().string());
    }
    return names;
  }

  private:
  std::filesystem::path m_path;
};

/// Run `f`, expect an InputError whose message contains every one of `parts`; returns the message.
inline std::string expect_input_error(
    const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message \"" << message << "\" lacks \"" << part << "\"";
    }
    return message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got " << typeid(e).name() << ": " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return {};
}

} // namespace elastolearn::io::test
