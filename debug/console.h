// simbot debug's command line: gdb's commands where they fit, read from a
// terminal (GNU readline: line editing and history) or from a file
// (--batch, each command echoed after the prompt so that the output is a
// transcript), answered on an output stream.
#pragma once
#include <iosfwd>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "debug/session.h"

namespace simbot::debug {

// Where command lines come from.
class LineSource {
 public:
  virtual ~LineSource() = default;
  // The next line; false at the end of the input.
  virtual bool next(std::string& line) = 0;
  // Lines read are echoed after the prompt (a transcript).
  virtual bool echo() const = 0;
};
// The terminal, with readline's editing and history.
std::unique_ptr<LineSource> terminalLines();
// A file's lines, or a stream's (stdin that is not a terminal).
std::unique_ptr<LineSource> streamLines(std::istream& in, bool echo);

class Console final : public Controller {
 public:
  Console(LineSource& lines, std::ostream& out) : lines_(lines), out_(out) {}
  Resume stopped(Session& session, const Stop& why) override;
  // Commands that failed (batch runs exit 1 if any did).
  int errors() const { return errors_; }

 private:
  // One command; true with `how` set when it resumes the robot.
  bool execute(Session& s, const std::string& line, Resume& how);
  void report(Session& s, const Stop& why);
  void showDisplays(Session& s);
  void showLocation(Session& s, int robot);
  void printExpression(Session& s, const std::string& expression, const std::string& label);
  void breakCommand(Session& s, std::string args, bool temporary);
  void info(Session& s, const std::string& what);
  void list(Session& s, std::string args);
  void backtrace(Session& s);

  LineSource& lines_;
  std::ostream& out_;
  std::vector<std::pair<int, std::string>> displays_;
  int nextDisplay_ = 1;
  int errors_ = 0;
  std::string lastCommand_;  // an empty line repeats it, as in gdb
  // The last resuming command, to report what stepi ran.
  Resume last_;
  uint32_t lastPc_ = 0;
  Tick lastTick_ = 0;
  int repeat_ = 0;  // `step 3`: steps still to take
  int listRobot_ = 0, listLine_ = 0;
  std::set<int> temporaries_;  // tbreak's breakpoints, named so when they stop
};

}  // namespace simbot::debug
