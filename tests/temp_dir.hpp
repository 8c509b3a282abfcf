#pragma once
// A fresh directory per test under the system's temporary directory, named after the test and the process, removed
// afterwards (kept after a failure when asked, as evidence). Shared by the tests that write files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace haet::testing {

class TempDirTest : public ::testing::Test {
protected:
    /// `prefix` names the directory (haet_PREFIX_TEST_PID); `keepOnFailure` leaves it after a failed test.
    explicit TempDirTest(std::string prefix, bool keepOnFailure = false)
        : prefix_(std::move(prefix)), keep_(keepOnFailure) {}
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               ("haet_" + prefix_ + "_" + std::string(info->name()) + "_" + std::to_string(getpid()));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        if (!(keep_ && HasFailure())) std::filesystem::remove_all(dir_);
    }
    static std::string slurp(const std::filesystem::path& p) {
        std::ifstream in(p, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }

    std::filesystem::path dir_;

private:
    std::string prefix_;
    bool keep_;
};

}  // namespace haet::testing
