// simbot explain TRACE.jsonl [--robot A|B] [--markdown | --json]: the
// report of tools/explain.h on stdout.
#include <iostream>
#include <memory>

#include "tools/commands.h"
#include "tools/explain.h"
#include "tools/json_text.h"
#include "tools/runner.h"

namespace simbot::tools {

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
              explain::Report report = explain::explainFile(o->trace);
              if (!o->robot.empty()) report = explain::onlyRobot(report, o->robot == "A" ? 0 : 1);
              if (o->json)
                std::cout << dumpJson(explain::json(report), 2) << '\n';
              else if (o->markdown)
                std::cout << explain::markdown(report);
              else
                std::cout << explain::text(report);
              return 0;
            } catch (const ToolError& e) {
              std::cerr << e.what();
              return 1;
            }
          }};
}

}  // namespace simbot::tools
