// files/ (namespace simbot::files): the host's files as simbot's commands
// use them, so that no run ever loses work.
//
// An input is opened without waiting (O_NONBLOCK: a FIFO is refused, never
// waited on) and must be a regular file no larger than the limit stated
// beside its kind. An output is written to a temporary file beside it and
// renamed over it only when complete: a run refused for bad input, a
// failed write, an exception or a kill leaves the old file as it was (a
// signal also removes the temporary file). No output may be the same file
// as an input or as another output; files are compared by device and
// inode, so a second name for a file (a link, "./x", "../d/x") is caught.
//
// The lowest of simbot's parts above the standard library: compiler/,
// config/, sinks/, reports/, batch/ and cli/ use it; it uses none of them.
// Its errors carry the reason alone, for each caller's own format.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace simbot::files {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Input::readLine's line past its limit.
struct LineTooLong : Error {
  using Error::Error;
};

// Profiles, hardware files, scenarios and sweep files: 1 MiB (the shipped
// default profile is 9 KB; a larger file is not a configuration).
constexpr std::uint64_t kMaxConfigBytes = std::uint64_t{1} << 20;
// Traces read back (view, explain, Python's read_trace): 16 GiB (a 180-s
// match with --trace-costate wrote 181 MB).
constexpr std::uint64_t kMaxTraceBytes = std::uint64_t{16} << 30;
// A line of a trace read back: 8 MiB. The longest record simbot writes is
// a robot's, which carries its program's source: at most the compiler's
// 1 MiB (compiler::kMaxSourceBytes), at most 6 MiB as JSON (a control
// byte is written as 6 characters, \u0001), with a path of at most 4096
// bytes (24 KiB as JSON) and some 30 numbers. A longer line is no record of
// simbot's, and is refused without being held whole.
constexpr std::size_t kMaxTraceLineBytes = std::size_t{8} << 20;

// The whole of the regular file `path`, of at most `maxBytes`. Error: "no
// such file", "it is a directory", "not a regular file", "N bytes is more
// than the limit of M", or the system's reason.
std::string readInput(const std::string& path, std::uint64_t maxBytes);

// What a batch's --resume compares: a file's contents as
// "fnv1a64:HEX" (FNV-1a, 64 bits: a change of any byte changes it, with
// the odds of a chance match 2^-64), or "unreadable: REASON".
std::string fingerprint(const std::string& path);

// A regular file of at most `maxBytes`, open for reading as a stream.
class Input {
 public:
  Input(const std::string& path, std::uint64_t maxBytes);
  ~Input();
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;
  std::FILE* file() const { return file_; }
  // The next line, without its '\n', into `line`; false at the end of the
  // file. `whole`: it ended in '\n' (the last line of a file cut short
  // does not). A line of more than `maxBytes` is Error "a line of more than
  // N bytes" once that much of it is read: its rest is never held, so a
  // 1-GB line costs no more memory than the limit. Error with the system's
  // reason when a read fails; std::bad_alloc passes through. Not to be
  // mixed with reads through file().
  bool readLine(std::string& line, bool& whole, std::size_t maxBytes);

 private:
  std::FILE* file_ = nullptr;
  std::string buffer_;  // read from the file, not yet returned
  std::size_t at_ = 0;  // where in buffer_ the next line begins
};

// A file named on the command line and what it is to the run, for messages:
// {"P.dc", "the program"}, {"t.jsonl", "--trace"}.
struct Named {
  std::string path;
  std::string role;
};

// Error naming both when an output is the same file as an input, or two
// outputs are one file (by device and inode when the file exists, by its
// absolute, normalised name when it does not yet).
void checkDistinct(const std::vector<Named>& inputs, const std::vector<Named>& outputs);

// An output that replaces `path` only when commit() succeeds. A path that
// names an existing file that is not regular (/dev/null, a terminal, a
// pipe) is written in place. The new file takes the old one's permissions,
// or the umask's for a new file.
class Output {
 public:
  // Opens the temporary file now: a directory that cannot be written is an
  // Error before the run, and the old file is untouched.
  explicit Output(const std::string& path);
  ~Output();  // without commit(): the temporary file is removed
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  std::FILE* file() const { return file_; }
  const std::string& path() const { return path_; }
  // Flushes, syncs, closes and renames into place; Error with the system's
  // reason (the old file is kept; the temporary file is removed, or, when
  // only the rename failed, kept and named in the message).
  void commit();
  bool committed() const { return committed_; }

 private:
  void discard();
  std::string path_, temporary_;
  std::FILE* file_ = nullptr;
  int slot_ = -1;  // in the registry that the signal handler empties
  bool committed_ = false;
};

// Writes `text` to `path` through an Output.
void writeWhole(const std::string& path, const std::string& text);

// SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE and SIGXFSZ (when not ignored)
// remove every open Output's temporary file and
// then end the process by the signal, as before (cli/main.cpp installs it
// once; a batch's own stop handler takes over while the batch runs).
void removeTemporariesOnSignals();

}  // namespace simbot::files
