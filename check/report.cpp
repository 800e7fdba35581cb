// check/report.cpp -- simbot check's report: text for a terminal, JSON,
// and JUnit XML for a CI or an autograder (one test case per check and
// seed, as JUnit's schema has them: <testsuites><testsuite><testcase>,
// a <failure> or <skipped> child when it did not pass).
#include <fmt/format.h>

#include "check/check.h"

namespace simbot::check {

namespace {

const char* statusWord(Status s) {
  switch (s) {
    case Status::Passed:
      return "passed";
    case Status::Failed:
      return "failed";
    case Status::Skipped:
      return "skipped";
  }
  return "?";
}

std::string caseName(const Case& c) { return fmt::format("{} (seed {})", c.check, c.seed); }

// Text as XML character data or an attribute value: the five markup
// characters escaped, and control characters other than tab and newline
// (which XML 1.0 cannot carry) written as '?'.
std::string xmlText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\n' ? '?' : ch;
    }
  }
  return out;
}

}  // namespace

std::string reportText(const Report& report) {
  std::string out;
  for (const Case& c : report.cases) {
    const char* word = c.status == Status::Passed   ? "PASS"
                       : c.status == Status::Failed ? "FAIL"
                                                    : "SKIP";
    out += fmt::format("{}  {}: {}\n", word, caseName(c), c.message);
  }
  out += fmt::format("{}: {} passed, {} failed, {} skipped\n", report.program,
                     report.count(Status::Passed), report.count(Status::Failed),
                     report.count(Status::Skipped));
  return out;
}

nlohmann::json reportJson(const Report& report) {
  nlohmann::json cases = nlohmann::json::array();
  for (const Case& c : report.cases)
    cases.push_back({{"check", c.check},
                     {"seed", c.seed},
                     {"status", statusWord(c.status)},
                     {"message", c.message}});
  return {{"program", report.program},
          {"expectations", report.expectations},
          {"passed", report.count(Status::Passed)},
          {"failed", report.count(Status::Failed)},
          {"skipped", report.count(Status::Skipped)},
          {"cases", cases}};
}

std::string junitXml(const Report& report) {
  const std::string suite = xmlText("simbot check " + report.program);
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  const auto counts =
      fmt::format(R"(tests="{}" failures="{}" errors="0" skipped="{}")", report.cases.size(),
                  report.count(Status::Failed), report.count(Status::Skipped));
  out += fmt::format("<testsuites name=\"{}\" {}>\n", suite, counts);
  out += fmt::format("  <testsuite name=\"{}\" {}>\n", suite, counts);
  for (const Case& c : report.cases) {
    const std::string head = fmt::format("    <testcase classname=\"{}\" name=\"{}\"",
                                         xmlText(report.expectations), xmlText(caseName(c)));
    if (c.status == Status::Passed) {
      out += head + "/>\n";
      continue;
    }
    const char* tag = c.status == Status::Failed ? "failure" : "skipped";
    out += head + ">\n";
    out += fmt::format("      <{} message=\"{}\"/>\n", tag, xmlText(c.message));
    out += "    </testcase>\n";
  }
  out += "  </testsuite>\n</testsuites>\n";
  return out;
}

}  // namespace simbot::check
