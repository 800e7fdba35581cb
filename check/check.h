// check/ (namespace simbot::check): `simbot check` (docs/check.md). A
// program is run as robot A over the seeds an expectations file names
// (config.h loadExpectations), against its opponent, and each [[check]] is
// judged on each run: on the run's result (faults, hits, shots, scatter
// shots, overwritten sends, frames) or on its trace records in simulated
// time (a step: every record matching `after` followed within `within_s`
// by one matching `expect`). Reported as text, JSON or JUnit XML.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "config/config.h"

namespace simbot::check {

enum class Status : std::uint8_t { Passed, Failed, Skipped };

// One check on one seed (a JUnit test case).
struct Case {
  std::string check;
  std::uint64_t seed = 0;
  Status status = Status::Passed;
  std::string message;  // why it failed or was skipped; what held when it passed
};

struct Report {
  std::string program, expectations;
  std::vector<Case> cases;  // seed by seed, checks in file order
  int count(Status s) const;
};

// Plays the program against the file's opponent on each of its seeds and
// judges every check. Throws the runs' UserError and ConfigError (a
// program that does not compile, a profile that is not there).
Report runChecks(const std::string& program, const config::Expectations& expectations);

// "PASS|FAIL|SKIP  CHECK (seed S): MESSAGE" per case, then the counts.
std::string reportText(const Report& report);
nlohmann::json reportJson(const Report& report);
// One <testsuite> of one <testcase> per check and seed (name "CHECK (seed
// S)", classname the expectations file), <failure> or <skipped> with the
// message.
std::string junitXml(const Report& report);

}  // namespace simbot::check
