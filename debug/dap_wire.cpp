// debug/dap_wire.cpp -- simbot dap's transport (dap_wire.h): framing,
// JSON with its depth bounded, the request's envelope checked, the reader
// thread and its queue, the typed argument readers.
#include "debug/dap_wire.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <condition_variable>
#include <deque>
#include <istream>
#include <limits>
#include <mutex>
#include <set>
#include <thread>

#include "debug/session.h"
#include "debug/trim.h"
#include "timebase/written.h"

namespace simbot::debug {

namespace {

using nlohmann::json;

constexpr std::string_view kContentLength = "content-length:";

char lower(int c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

// Where "Content-Length:" (any case) starts in `bytes` at or after `from`.
size_t findHeader(std::string_view bytes, size_t from) {
  if (bytes.size() < kContentLength.size()) return std::string_view::npos;
  for (size_t at = from; at + kContentLength.size() <= bytes.size(); ++at) {
    size_t k = 0;
    while (k < kContentLength.size() && lower(bytes[at + k]) == kContentLength[k]) ++k;
    if (k == kContentLength.size()) return at;
  }
  return std::string_view::npos;
}

bool isToken(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

// `key`'s value as an integer in [min, max], checked before narrowing.
std::optional<int64_t> integerIn(const json& v, int64_t min, int64_t max) {
  if (v.is_number_unsigned()) {
    const auto u = v.get<uint64_t>();
    if (max < 0 || u > static_cast<uint64_t>(max)) return std::nullopt;
    const auto i = static_cast<int64_t>(u);
    return i >= min ? std::optional<int64_t>(i) : std::nullopt;
  }
  if (v.is_number_integer()) {
    const auto i = v.get<int64_t>();
    return i >= min && i <= max ? std::optional<int64_t>(i) : std::nullopt;
  }
  return std::nullopt;
}

// Follows a JSON text byte by byte (strings and escapes too) to find
// where an object that opens with its first byte closes, counting
// brackets in a plain integer: no recursion, whatever the depth.
class ObjectEnd {
 public:
  // Whether `c` closes the object.
  bool feed(char c) {
    if (inString_) {
      if (escaped_)
        escaped_ = false;
      else if (c == '\\')
        escaped_ = true;
      else if (c == '"')
        inString_ = false;
      return false;
    }
    if (c == '"') inString_ = true;
    if (c == '{' || c == '[') ++depth_;
    return (c == '}' || c == ']') && --depth_ == 0;
  }

 private:
  int64_t depth_ = 0;
  bool inString_ = false, escaped_ = false;
};

// nlohmann's SAX interface: a message's depth, and its seq and command
// (members of the outermost object), without building its value.
class Outline {
 public:
  int deepest = 0;
  int64_t seq = -1;     // -1: none that is an integer, 0 or more
  std::string command;  // "": none that is a string

  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(json::number_integer_t v) {
    if (depth_ == 1 && key_ == Key::Seq) seq = v >= 0 ? v : -1;
    return value();
  }
  bool number_unsigned(json::number_unsigned_t v) {
    if (depth_ == 1 && key_ == Key::Seq)
      seq = v <= static_cast<uint64_t>(std::numeric_limits<int64_t>::max())
                ? static_cast<int64_t>(v)
                : -1;
    return value();
  }
  bool number_float(json::number_float_t, const json::string_t&) {
    if (depth_ == 1 && key_ == Key::Seq) seq = -1;
    return value();
  }
  bool string(json::string_t& s) {
    if (depth_ == 1 && key_ == Key::Seq) seq = -1;
    if (depth_ == 1 && key_ == Key::Command) command = s;
    return value();
  }
  bool binary(json::binary_t&) { return value(); }
  bool start_object(size_t) { return open(); }
  bool start_array(size_t) { return open(); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(json::string_t& k) {
    if (depth_ == 1) key_ = k == "seq" ? Key::Seq : k == "command" ? Key::Command : Key::Other;
    return true;
  }
  bool parse_error(size_t, const std::string&, const nlohmann::detail::exception&) { return false; }

 private:
  enum class Key : uint8_t { Other, Seq, Command };
  bool value() {
    if (depth_ == 1) key_ = Key::Other;
    return true;
  }
  bool open() {
    if (depth_ == 1 && key_ == Key::Seq) seq = -1;
    if (depth_ == 1 && key_ == Key::Command) command.clear();
    deepest = std::max(deepest, ++depth_);
    return true;
  }
  bool close() {
    --depth_;
    return value();
  }
  int depth_ = 0;
  Key key_ = Key::Other;
};

const json* member(const json& args, const char* key) {
  if (!args.is_object()) return nullptr;
  const auto it = args.find(key);
  return it == args.end() || it->is_null() ? nullptr : &*it;
}

}  // namespace

std::string excerpt(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 40))
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (text.size() > 40) out += "...";
  return out;
}

// ---- the reader ------------------------------------------------------------------

DapReader::DapReader(std::istream& in) : in_(in) {}

int DapReader::get() {
  if (!pushedBack_.empty()) {
    const auto c = static_cast<unsigned char>(pushedBack_.back());
    pushedBack_.pop_back();
    return c;
  }
  const auto c = in_.rdbuf()->sbumpc();
  return std::istream::traits_type::eq_int_type(c, std::istream::traits_type::eof())
             ? -1
             : static_cast<unsigned char>(std::istream::traits_type::to_char_type(c));
}

int DapReader::peek() {
  const int c = get();
  if (c >= 0) pushedBack_.push_back(static_cast<char>(c));
  return c;
}

void DapReader::unget(std::string_view bytes) { pushedBack_.append(bytes.rbegin(), bytes.rend()); }

void DapReader::problem(std::string text, int64_t seq, std::string command) {
  DapIncoming m;
  m.kind = DapIncoming::Kind::Problem;
  m.problem = std::move(text);
  m.seq = seq;
  m.command = std::move(command);
  ready_.push_back(std::move(m));
}

DapIncoming DapReader::next() {
  while (ready_.empty()) {
    if (ended_) return DapIncoming{};
    if (resync_) {
      resync_ = false;
      if (!skipToHeader()) {
        ended_ = true;
        continue;
      }
    }
    readHeaderBlock();
  }
  DapIncoming m = std::move(ready_.front());
  ready_.pop_front();
  return m;
}

// Discards bytes up to the next "Content-Length:", which is read again as
// a header's start; false at the end of the input.
bool DapReader::skipToHeader() {
  size_t matched = 0;  // "content-length:" has no prefix that recurs inside it
  for (;;) {
    const int c = get();
    if (c < 0) return false;
    if (lower(c) == kContentLength[matched]) {
      if (++matched == kContentLength.size()) {
        unget("Content-Length:");
        return true;
      }
    } else {
      matched = lower(c) == kContentLength[0] ? 1 : 0;
    }
  }
}

// A body that came after a header block without a usable Content-Length:
// a JSON object read up to its closing brace (strings and escapes
// followed), so that its seq and command can be answered. None if the
// next byte does not open an object, or the object does not end within
// kDapMaxBodyBytes or before the input does.
std::optional<std::string> DapReader::orphanBody() {
  if (peek() != '{') return std::nullopt;
  std::string bytes;
  ObjectEnd end;
  for (;;) {
    const int c = get();
    if (c < 0 || bytes.size() >= kDapMaxBodyBytes) return std::nullopt;
    bytes.push_back(static_cast<char>(c));
    if (end.feed(static_cast<char>(c))) return bytes;
  }
}

void DapReader::readHeaderBlock() {
  std::optional<uint64_t> length;
  std::string bad;  // the block's first fault
  std::vector<std::string> ignored;
  int lines = 0;
  for (;;) {
    std::string line;
    bool end = false;
    for (;;) {
      const int c = get();
      if (c < 0) {
        end = true;
        break;
      }
      if (c == '\n') break;
      if (line.size() >= kDapMaxHeaderLineBytes) {
        problem(fmt::format("a header line longer than {} bytes ('{}')", kDapMaxHeaderLineBytes,
                            excerpt(line)));
        unget(std::string(1, static_cast<char>(c)));
        resync_ = true;
        return;
      }
      line.push_back(static_cast<char>(c));
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (end) {
      if (lines > 0 || !trim(line, " \t").empty())
        problem(
            "the input ended inside a header block (a message starts with Content-Length: N "
            "and a blank line)");
      ended_ = true;
      return;
    }
    if (line.empty()) {
      if (lines == 0) continue;  // blank lines between messages
      break;
    }
    if (++lines > kDapMaxHeaderLines) {
      problem(fmt::format("a header block of more than {} lines", kDapMaxHeaderLines));
      resync_ = true;
      return;
    }
    const size_t colon = line.find(':');
    if (colon == std::string::npos || !isToken(line.substr(0, colon))) {
      // Bytes a message left over (its Content-Length too small), or a
      // client that sent no header: read again from the next header in
      // the line, if there is one.
      if (const size_t at = findHeader(line, 1); at != std::string::npos) {
        unget(line.substr(at) + "\n");
        line.resize(at);
      }
      problem(
          fmt::format("'{}' is not a header line (a message starts with Content-Length: N "
                      "and a blank line)",
                      excerpt(line)));
      resync_ = true;
      return;
    }
    std::string name = line.substr(0, colon);
    for (char& c : name) c = lower(c);
    const std::string value = trim(std::string_view(line).substr(colon + 1), " \t");
    if (name != "content-length") {
      ignored.push_back(line.substr(0, colon));
      continue;
    }
    uint64_t n = 0;
    const auto [stop, error] = std::from_chars(value.data(), value.data() + value.size(), n);
    const bool digits = !value.empty() && std::all_of(value.begin(), value.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    if (!bad.empty()) continue;
    if (!digits || stop != value.data() + value.size()) {
      bad = fmt::format("Content-Length '{}' is not a byte count", excerpt(value));
    } else if (error != std::errc() || n > kDapMaxBodyBytes) {
      bad = fmt::format("Content-Length {} is over the limit of {} bytes (4 MB)", excerpt(value),
                        kDapMaxBodyBytes);
    } else if (length && *length != n) {
      bad = fmt::format("two Content-Lengths ({} and {})", *length, n);
    } else {
      length = n;
    }
  }
  if (!ignored.empty()) {
    std::string names;
    for (const std::string& n : ignored) names += (names.empty() ? "'" : ", '") + excerpt(n) + "'";
    problem(fmt::format("header {} ignored: DAP has only Content-Length", names));
  }
  if (bad.empty() && !length) bad = "a header block without Content-Length";
  if (!bad.empty()) {
    if (const std::optional<std::string> orphan = orphanBody()) {
      body(*orphan, bad);
    } else {
      problem(bad + "; skipped to the next Content-Length");
      resync_ = true;
    }
    return;
  }
  std::string bytes(*length, '\0');
  size_t got = 0;
  while (got < bytes.size() && !pushedBack_.empty()) {
    bytes[got++] = static_cast<char>(pushedBack_.back());
    pushedBack_.pop_back();
  }
  while (got < bytes.size()) {
    const auto n =
        in_.rdbuf()->sgetn(bytes.data() + got, static_cast<std::streamsize>(bytes.size() - got));
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  if (got < bytes.size()) {
    problem(fmt::format("the input ended {} bytes into a message of {}", got, bytes.size()));
    ended_ = true;
    return;
  }
  body(bytes, "");
}

void DapReader::body(const std::string& bytes, const std::string& framing) {
  // Read once without building anything (nlohmann's parser is iterative):
  // whether it is JSON, how deep it nests, its seq and command. Only then
  // is the value built, never one deeper than kDapMaxDepth.
  Outline outline;
  if (!json::sax_parse(bytes, &outline)) {
    // A Content-Length larger than its body: the next message's header
    // (or a part of it) follows the body inside these bytes. Where the
    // body is an object, it ends at its closing brace; else at the first
    // "Content-Length:" (the part before has none). The rest is read again
    // as the next header block.
    size_t at = std::string::npos;
    if (!bytes.empty() && bytes[0] == '{') {
      ObjectEnd end;
      for (size_t k = 0; k + 1 < bytes.size() && at == std::string::npos; ++k)
        if (end.feed(bytes[k])) at = k + 1;
    }
    if (at == std::string::npos) at = findHeader(bytes, 1);
    if (at != std::string::npos) {
      unget(std::string_view(bytes).substr(at));
      body(bytes.substr(0, at),
           framing.empty()
               ? fmt::format("a Content-Length of {} for a message of {} bytes", bytes.size(), at)
               : framing);
      return;
    }
    problem(framing.empty() ? fmt::format("a message that is not JSON ('{}')", excerpt(bytes))
                            : framing);
    return;
  }
  const int64_t seq = outline.seq;
  const std::string command = outline.command;
  if (!framing.empty()) return problem(framing, seq, command);
  if (outline.deepest > kDapMaxDepth)
    return problem(fmt::format("a message nested more than {} deep", kDapMaxDepth), seq, command);
  json m = json::parse(bytes, nullptr, false);
  if (!m.is_object()) return problem("a message must be a JSON object");
  const auto type = m.find("type");
  if (type == m.end() || !type->is_string())
    return problem("'type' must be the string \"request\"", seq, command);
  // A response (to a reverse request: this adapter sends none) needs no
  // answer.
  if (type->get<std::string>() == "response") return;
  if (type->get<std::string>() != "request")
    return problem(
        fmt::format("'type' \"{}\": a client sends requests", excerpt(type->get<std::string>())),
        seq, command);
  if (seq < 0) return problem("'seq' must be an integer, 0 or more", -1, command);
  const auto c = m.find("command");
  if (c == m.end() || !c->is_string() || command.empty())
    return problem("'command' must be a non-empty string", seq, "");
  DapIncoming request;
  request.kind = DapIncoming::Kind::Request;
  request.seq = seq;
  request.command = command;
  if (const auto a = m.find("arguments"); a != m.end() && !a->is_null()) {
    if (!a->is_object()) return problem("'arguments' must be an object", seq, command);
    request.arguments = std::move(*a);
  }
  ready_.push_back(std::move(request));
}

// ---- the reader thread -------------------------------------------------------------

struct DapInbox::Shared {
  explicit Shared(std::istream& in) : reader(in) {}
  DapReader reader;  // the reader thread's
  std::atomic<bool> interrupt{false};
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<DapIncoming> queue;
  // Waiting in the queue: the requests that set the flag as they came,
  // the disconnects and terminates among them, the requests that resume.
  int interrupting = 0, quits = 0, resumes = 0;
  bool finished = false;  // nothing more will be queued
};

namespace {

bool isQuit(const DapIncoming& m) {
  return m.kind == DapIncoming::Kind::End ||
         (m.kind == DapIncoming::Kind::Request &&
          (m.command == "disconnect" || m.command == "terminate"));
}

bool isPause(const DapIncoming& m) {
  return m.kind == DapIncoming::Kind::Request && m.command == "pause";
}

// A request that (may) start a command running.
bool isResume(const DapIncoming& m) {
  static const std::set<std::string, std::less<>> resuming = {
      "configurationDone", "continue", "next", "stepIn", "stepOut", "stepBack", "reverseContinue"};
  return m.kind == DapIncoming::Kind::Request && resuming.count(m.command) > 0;
}

}  // namespace

DapInbox::DapInbox(std::istream& in) : shared_(std::make_shared<Shared>(in)) {
  thread_ = std::thread([s = shared_] { readAll(s); });
}

DapInbox::~DapInbox() {
  bool finished = false;
  {
    const std::lock_guard lock(shared_->mutex);
    finished = shared_->finished;
  }
  // A reader still waiting for input (the session ended another way) is
  // left to the process's end; it holds its own share of the state.
  if (finished)
    thread_.join();
  else
    thread_.detach();
}

std::atomic<bool>* DapInbox::interrupt() { return &shared_->interrupt; }

DapIncoming DapInbox::take() {
  std::unique_lock lock(shared_->mutex);
  shared_->changed.wait(lock, [&] { return !shared_->queue.empty() || shared_->finished; });
  if (shared_->queue.empty()) return DapIncoming{};
  DapIncoming m = std::move(shared_->queue.front());
  shared_->queue.pop_front();
  shared_->interrupting -= m.interrupting;
  if (isQuit(m) && m.interrupting) --shared_->quits;
  if (isResume(m)) --shared_->resumes;
  return m;
}

void DapInbox::resuming() {
  // Under the lock: a request that sets the flag now is seen here, or sets
  // it after this.
  const std::lock_guard lock(shared_->mutex);
  if (shared_->interrupting > 0) shared_->interrupt.store(true);
}

bool DapInbox::quitWaiting() const {
  const std::lock_guard lock(shared_->mutex);
  return shared_->quits > 0;
}

bool DapInbox::pauseNext() const {
  const std::lock_guard lock(shared_->mutex);
  return !shared_->queue.empty() && isPause(shared_->queue.front()) &&
         shared_->queue.front().interrupting;
}

void DapInbox::readAll(const std::shared_ptr<Shared>& s) {
  for (;;) {
    DapIncoming m = s->reader.next();
    const bool quit = isQuit(m), pause = isPause(m);
    // Nothing is read after a disconnect: the client has finished.
    const bool last = m.kind == DapIncoming::Kind::End ||
                      (m.kind == DapIncoming::Kind::Request && m.command == "disconnect");
    const std::lock_guard lock(s->mutex);
    // One queued behind a resuming request (a client that sends requests
    // without waiting for answers, a script) is for after the command that
    // request starts, in turn; one with none before it is for the command
    // running now, if any.
    const bool interrupts = (quit || pause) && s->resumes == 0;
    s->resumes += isResume(m);
    m.interrupting = interrupts;
    s->queue.push_back(std::move(m));
    s->quits += quit && interrupts;
    s->interrupting += interrupts;
    s->finished = last;
    if (interrupts) s->interrupt.store(true);
    s->changed.notify_all();
    if (last) return;
  }
}

// ---- arguments ----------------------------------------------------------------------

std::optional<std::string> stringArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (!v) return std::nullopt;
  if (!v->is_string()) throw Error(fmt::format("'{}' must be a string", key));
  return v->get<std::string>();
}

std::optional<int64_t> integerArgument(const json& args, const char* key, int64_t min,
                                       int64_t max) {
  const json* v = member(args, key);
  if (!v) return std::nullopt;
  const std::optional<int64_t> i = integerIn(*v, min, max);
  if (!i) throw Error(fmt::format("'{}' must be an integer from {} to {}", key, min, max));
  return i;
}

std::optional<uint64_t> unsignedArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (!v) return std::nullopt;
  if (!v->is_number_unsigned())
    throw Error(fmt::format("'{}' must be a whole number, 0 or more", key));
  return v->get<uint64_t>();
}

std::optional<timebase::Tick> runLengthArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (!v) return std::nullopt;
  try {
    if (v->is_string()) return timebase::parseRunLength(v->get<std::string>());
    // A number is seconds, as JSON wrote it (its shortest decimal).
    if (v->is_number()) return timebase::runLengthFromSeconds(v->get<double>());
  } catch (const timebase::TimeError& e) {
    throw Error(fmt::format("'{}': {}", key, e.what()));
  }
  throw Error(fmt::format("'{}' must be a number of seconds or a time such as \"800ms\"", key));
}

std::optional<bool> boolArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) throw Error(fmt::format("'{}' must be true or false", key));
  return v->get<bool>();
}

const json* objectArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (v && !v->is_object()) throw Error(fmt::format("'{}' must be an object", key));
  return v;
}

const json* arrayArgument(const json& args, const char* key) {
  const json* v = member(args, key);
  if (v && !v->is_array()) throw Error(fmt::format("'{}' must be an array", key));
  return v;
}

}  // namespace simbot::debug
