// simbot explain TRACE.jsonl [--robot A|B] [--markdown | --json]: the
// report of reports/explain.h on stdout.
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "reports/explain.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"

namespace simbot::cli {

Subcommand addExplainCommand(CLI::App& app) {
  struct Options {
    std::string trace, robot;
    bool markdown = false, json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd =
      app.add_subcommand("explain",
                         "a readable report of a recorded run: shots, stalls, overwritten sends, "
                         "handlers, contacts, referee actions, faults");
  cmd->add_option("TRACE", o->trace, "trace file (.jsonl) written with --trace")->required();
  cmd->add_option("--robot", o->robot, "only this robot's items (A or B)")
      ->check(CLI::IsMember({"A", "B"}));
  auto* markdown = cmd->add_flag("--markdown", o->markdown, "write the report as Markdown");
  cmd->add_flag("--json", o->json, "write the report as JSON")->excludes(markdown);
  return {cmd, [o] {
            try {
              reports::explain::Report report = reports::explain::explainFile(o->trace);
              if (!o->robot.empty())
                report = reports::explain::onlyRobot(report, o->robot == "A" ? 0 : 1);
              if (o->json)
                std::cout << sinks::dumpJson(reports::explain::json(report), 2) << '\n';
              else if (o->markdown)
                std::cout << reports::explain::markdown(report);
              else
                std::cout << reports::explain::text(report);
              return 0;
            } catch (const sinks::UserError& e) {
              std::cerr << e.what();
              return 1;
            }
          }};
}

}  // namespace simbot::cli
