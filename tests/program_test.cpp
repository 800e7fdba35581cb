// Runs every tests/programs/*.dc on the VM and compares its console with the
// `// expect: TEXT` comments in the file, in order (craftinginterpreters'
// test runner, in miniature).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/test_host.h"

namespace fs = std::filesystem;
using namespace simbot;

namespace {

std::vector<fs::path> programs() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(SIMBOT_SOURCE_DIR) / "tests" / "programs"))
    if (e.path().extension() == ".dc") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> expectations(const std::string& source) {
  std::vector<std::string> out;
  std::istringstream in(source);
  std::string line;
  const std::string marker = "// expect:";
  while (std::getline(in, line)) {
    const auto at = line.find(marker);
    if (at == std::string::npos) continue;
    std::string text = line.substr(at + marker.size());
    if (!text.empty() && text.front() == ' ') text.erase(0, 1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\r' || text.back() == '\t'))
      text.pop_back();
    out.push_back(text);
  }
  return out;
}

// A program that must fault: `// expect fault: MESSAGE` on the line where
// the robot faults (0: none expected). A MESSAGE ending in "..." is the
// message's beginning.
std::pair<int, std::string> expectedFault(const std::string& source) {
  std::istringstream in(source);
  std::string line;
  const std::string marker = "// expect fault: ";
  for (int number = 1; std::getline(in, line); ++number)
    if (const auto at = line.find(marker); at != std::string::npos)
      return {number, line.substr(at + marker.size())};
  return {0, ""};
}

class ProgramTest : public ::testing::TestWithParam<fs::path> {};

TEST_P(ProgramTest, ConsoleMatchesExpectations) {
  std::ifstream f(GetParam());
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string source = ss.str();
  auto result = compiler::compile(source, GetParam().filename().string());
  ASSERT_TRUE(result.image) << result.errors[0].format();
  testkit::TestHost host;
  vm::Vm v(*result.image, host, vm::makeCostTable(vm::calibratedKnobs()));
  const vm::Tick limit = 600 * vm::kTicksPerSecond;
  const auto stop = host.runUntil(v, limit);
  const auto [faultLine, faultMessage] = expectedFault(source);
  if (faultLine > 0) {
    ASSERT_NE(v.fault(), nullptr) << "no fault; expected '" << faultMessage << "'";
    if (faultMessage.ends_with("..."))
      EXPECT_EQ(v.fault()->message.substr(0, faultMessage.size() - 3),
                faultMessage.substr(0, faultMessage.size() - 3));
    else
      EXPECT_EQ(v.fault()->message, faultMessage);
    EXPECT_EQ(v.fault()->line, faultLine);
  } else {
    ASSERT_EQ(v.fault(), nullptr) << v.fault()->message << " at line " << v.fault()->line;
    ASSERT_EQ(stop, vm::Stop::Halted) << "main did not return within 600 simulated seconds";
  }
  const auto expected = expectations(source);
  ASSERT_TRUE(!expected.empty() || faultLine > 0) << "no // expect: lines";
  for (size_t i = 0; i < std::max(expected.size(), host.consoleLines.size()); ++i) {
    const std::string want = i < expected.size() ? expected[i] : "<nothing>";
    std::string got = i < host.consoleLines.size() ? host.consoleLines[i] : "<nothing>";
    while (!got.empty() && (got.back() == ' ' || got.back() == '\t')) got.pop_back();
    EXPECT_EQ(want, got) << "console line " << i + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Programs, ProgramTest, ::testing::ValuesIn(programs()),
                         [](const auto& param_info) {
                           std::string n = param_info.param.stem().string();
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

}  // namespace
