// simbot check PROGRAM --expect FILE.toml [--junit OUT.xml] [--json]: the
// program's runs judged against an expectations file (check/check.h,
// docs/check.md). Exit status 0 when no check failed, 1 otherwise (and
// for a bad file or program, with its one-line error).
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "check/check.h"
#include "cli/commands.h"
#include "files/files.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"

namespace simbot::cli {

Subcommand addCheckCommand(CLI::App& app) {
  struct Options {
    std::string program, expect, junit;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "check",
      "judge a program's runs against an expectations file (no fault, hits, shots, steps in "
      "simulated time); JUnit XML for a CI or an autograder");
  cmd->add_option("PROGRAM", o->program, "the program to check (robot A)")->required();
  cmd->add_option("--expect", o->expect, "the expectations file (TOML; docs/check.md)")->required();
  cmd->add_option("--junit", o->junit, "also write the results as JUnit XML to this file");
  cmd->add_flag("--json", o->json, "print the results as JSON");
  return {cmd, [o] {
            const config::Expectations e = config::loadExpectations(o->expect);
            // The JUnit file is opened before the runs: a path that cannot be
            // written is an error now, not after them.
            std::unique_ptr<files::Output> junit;
            if (!o->junit.empty()) {
              runs::checkFiles({{o->program, "PROGRAM"}, {o->expect, "--expect"}},
                               {{o->junit, "--junit"}});
              try {
                junit = std::make_unique<files::Output>(o->junit);
              } catch (const files::Error& err) {
                throw sinks::UserError(fmt::format("simbot: --junit: {}\n", err.what()));
              }
            }
            const check::Report report = check::runChecks(o->program, e);
            if (junit) {
              const std::string xml = check::junitXml(report);
              try {
                if (std::fwrite(xml.data(), 1, xml.size(), junit->file()) != xml.size())
                  throw files::Error(o->junit + ": write failed");
                junit->commit();
              } catch (const files::Error& err) {
                throw sinks::UserError(fmt::format("simbot: --junit: {}\n", err.what()));
              }
            }
            if (o->json)
              std::cout << sinks::dumpJson(check::reportJson(report), 2) << '\n';
            else
              std::cout << check::reportText(report);
            return report.count(check::Status::Failed) > 0 ? 1 : 0;
          }};
}

}  // namespace simbot::cli
