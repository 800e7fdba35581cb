// simbot dap's transport (dap.h): Debug Adapter Protocol messages read from
// a byte stream, each after a "Content-Length: N" header block, checked
// before anything acts on them; a reader thread that queues them while the
// session runs; the typed readers of a request's arguments.
//
// Nothing a client sends ends the session: a message that cannot be used
// (bad framing, not JSON, nested too deeply, a field of the wrong type) is
// one Problem, answered by the server with an error response when the
// message's seq or command could be read, else with an `output` event,
// and the reader goes on with the next header block.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "timebase/tick.h"

namespace simbot::debug {

// A message body's largest size: 4 MB. The largest request a client sends
// in earnest is a setBreakpoints on a whole file (about 40 bytes a line:
// 0.4 MB for 10,000 lines); the value built from 4 MB of `[{},{},...]`
// peaks at 170 MB, of `[0,0,...]` at 90 MB (measured, in 0.6 s).
inline constexpr size_t kDapMaxBodyBytes = size_t{4} << 20;
// A header line's largest size (DAP's one header is about 20 bytes), and
// the most lines a header block may have.
inline constexpr size_t kDapMaxHeaderLineBytes = 1024;
inline constexpr int kDapMaxHeaderLines = 16;
// How deeply a message's JSON may nest: requests use 4 levels (a
// setBreakpoints' arguments.breakpoints[k].line); a launch configuration a
// few more. Deeper values are refused while they are parsed, so that no
// recursive copy, comparison or dump ever meets one.
inline constexpr int kDapMaxDepth = 64;

// One thing read from the client.
struct DapIncoming {
  enum class Kind : uint8_t {
    Request,  // a well-formed request
    Problem,  // a message that cannot be used: `problem` says why
    End,      // the input ended
  };
  Kind kind = Kind::End;
  int64_t seq = -1;     // Request; Problem: the seq, if it could be read (else -1)
  std::string command;  // Request; Problem: the command, if it could be read
  nlohmann::json arguments = nlohmann::json::object();  // Request: always an object
  std::string problem;                                  // Problem: one line, no newline
  bool interrupting = false;  // DapInbox: it set the interrupt flag as it came
};

// Reads messages from a stream, resynchronising after bad framing on the
// next "Content-Length:" header.
class DapReader {
 public:
  explicit DapReader(std::istream& in);
  DapReader(const DapReader&) = delete;
  DapReader& operator=(const DapReader&) = delete;

  // The next request, problem, or the end (and the end on every later call).
  DapIncoming next();

 private:
  int get();  // a byte, or -1 at the end
  int peek();
  void unget(std::string_view bytes);
  void readHeaderBlock();
  bool skipToHeader();
  std::optional<std::string> orphanBody();
  void body(const std::string& bytes, const std::string& framingProblem);
  void problem(std::string text, int64_t seq = -1, std::string command = "");

  std::istream& in_;
  std::string pushedBack_;  // bytes to read again before the stream's, last first
  bool ended_ = false;
  bool resync_ = false;            // skip to the next header block first
  std::deque<DapIncoming> ready_;  // read, not yet returned
};

// Reads requests on a thread of its own, so that the session's thread can
// be told to stop a running command: `disconnect`, `terminate`, `pause`
// (and the end of the input) set the interrupt flag the session runs with
// as soon as they arrive, unless a request that resumes the robot is
// queued before them (then they are for after the command it starts).
// Every message waits in the queue for the session's thread, and is
// answered in turn.
class DapInbox {
 public:
  explicit DapInbox(std::istream& in);
  ~DapInbox();
  DapInbox(const DapInbox&) = delete;
  DapInbox& operator=(const DapInbox&) = delete;

  // The flag to give Session::run.
  std::atomic<bool>* interrupt();
  // The session cleared the flag to resume (Controller::resuming): set it
  // again if a request that set it waits in the queue.
  void resuming();
  // The next message, waiting for it.
  DapIncoming take();
  // Whether a disconnect or terminate (or the end of the input) that set
  // the interrupt flag waits in the queue; whether the next message is a
  // pause that set it.
  bool quitWaiting() const;
  bool pauseNext() const;

 private:
  struct Shared;
  static void readAll(const std::shared_ptr<Shared>& s);
  std::shared_ptr<Shared> shared_;
  std::thread thread_;
};

// A client's text quoted in a one-line message: printable, at most 40
// characters.
std::string excerpt(std::string_view text);

// ---- a request's arguments ---------------------------------------------------
// Each reads `key` of an object (anything else has no keys): nullopt when
// it is absent or null; Error (session.h) "'key' must be ..." when it has
// the wrong type or is out of range. Integers are checked before any
// narrowing; a number with a fraction or an exponent is not an integer.

std::optional<std::string> stringArgument(const nlohmann::json& args, const char* key);
std::optional<int64_t> integerArgument(const nlohmann::json& args, const char* key, int64_t min,
                                       int64_t max);
std::optional<uint64_t> unsignedArgument(const nlohmann::json& args, const char* key);
// A run's length: a number of seconds or a string in timebase/written.h's
// grammar ("800ms", "9216t"), a whole number of ticks within the one
// run-length limit.
std::optional<timebase::Tick> runLengthArgument(const nlohmann::json& args, const char* key);
std::optional<bool> boolArgument(const nlohmann::json& args, const char* key);
// An object or an array: a pointer into `args` (null when absent or null).
const nlohmann::json* objectArgument(const nlohmann::json& args, const char* key);
const nlohmann::json* arrayArgument(const nlohmann::json& args, const char* key);

}  // namespace simbot::debug
