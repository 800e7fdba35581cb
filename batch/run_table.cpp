#include "batch/run_table.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "files/files.h"
#include "runs/play.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"

namespace simbot::batch {

namespace fs = std::filesystem;

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string csvLine(const CsvRow& fields) {
  std::string line;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (i) line += ',';
    line += csvField(fields[i]);
  }
  return line;
}

std::string csvRecord(const CsvRow& fields) { return csvLine(fields) + "\r\n"; }

std::vector<std::string> csvRecords(const std::string& text) {
  std::vector<std::string> records;
  bool quoted = false;
  size_t start = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '"') quoted = !quoted;
    if (text[i] == '\n' && !quoted) {
      const size_t end = i > start && text[i - 1] == '\r' ? i - 1 : i;
      records.push_back(text.substr(start, end - start));
      start = i + 1;
    }
  }
  return records;
}

CsvRow parseCsvLine(const std::string& line) {
  CsvRow fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"' && fields.back().empty()) {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  if (quoted) throw std::invalid_argument("an unterminated quoted field");
  return fields;
}

void writeFileAtomically(const std::string& path, const std::string& text) {
  try {
    files::writeWhole(path, text);
  } catch (const files::Error& e) {
    throw sinks::UserError(fmt::format("simbot: cannot write '{}': {}\n", path, e.what()));
  }
}

RowFile::RowFile(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0)
    throw sinks::UserError(
        fmt::format("simbot: cannot write '{}': {}\n", path, std::strerror(errno)));
}

RowFile::~RowFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool RowFile::append(const std::string& rows) {
  std::lock_guard lock(mutex_);
  if (failed_) return false;  // the batch is stopping; this run is done again by --resume
  const off_t before = ::lseek(fd_, 0, SEEK_END);
  size_t written = 0;
  while (before >= 0 && written < rows.size()) {
    const ssize_t n = ::write(fd_, rows.data() + written, rows.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    written += static_cast<size_t>(n);
  }
  if (before >= 0 && written == rows.size()) return true;
  // Each row whole or absent: what was written of this one goes, so that
  // rows written later (after space is freed) are never glued onto it.
  const int error = before < 0 ? errno : (errno ? errno : ENOSPC);
  failed_ = true;
  const bool rolledBack = before >= 0 && ::ftruncate(fd_, before) == 0;
  throw sinks::UserError(fmt::format(
      "simbot: writing '{}': {}; the batch stopped at once{} (--resume continues)\n", path_,
      std::strerror(error),
      rolledBack ? ", with every finished row whole in the table"
                 : fmt::format(", and the partial row could not be removed ({}): remove it "
                               "by hand",
                               std::strerror(errno))));
}

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

void makeOutputFolder(const std::string& dir) {
  std::error_code ec;
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec || (!dir.empty() && !fs::is_directory(dir)))
    throw sinks::UserError(fmt::format("simbot: cannot use '{}' for the outputs: {}\n", dir,
                                       ec ? ec.message() : "not a directory"));
}

void checkBatchOutputs(const std::vector<std::string>& inputs,
                       const std::vector<std::string>& outputs) {
  std::vector<files::Named> in, out;
  for (const auto& path : inputs) in.push_back({path, "the input"});
  for (const auto& path : outputs) out.push_back({path, "the output"});
  runs::checkFiles(in, out);
}

// ---- the settings file

BatchSettings::BatchSettings(std::string path, nlohmann::json settings, const std::string& version)
    : path_(std::move(path)), settings_(std::move(settings)) {
  settings_["simbot"] = version;
}

std::vector<std::string> BatchSettings::inputs() const {
  std::vector<std::string> paths;
  if (const auto contents = settings_.find("contents"); contents != settings_.end())
    for (const auto& [path, print] : contents->items()) paths.push_back(path);
  return paths;
}

void BatchSettings::checkResume(const std::string& what) const {
  nlohmann::json earlier;
  try {
    earlier = nlohmann::json::parse(files::readInput(path_, files::kMaxConfigBytes));
  } catch (const std::exception&) {
    throw sinks::UserError(fmt::format("simbot: --resume: '{}' is missing or unreadable\n", path_));
  }
  if (earlier != settings_)
    throw sinks::UserError(
        fmt::format("simbot: --resume: {} {}; run it again as it was, or choose another --out\n",
                    what, settingsChange(earlier, settings_)));
}

void BatchSettings::remove() const {
  std::error_code ec;
  fs::remove(path_, ec);
  if (ec)
    throw sinks::UserError(fmt::format("simbot: cannot remove '{}': {}\n", path_, ec.message()));
}

void BatchSettings::write() const {
  writeFileAtomically(path_, sinks::dumpJson(settings_, 2) + "\n");
}

// ---- the table

RunTable::RunTable(TableSpec spec)
    : spec_(std::move(spec)),
      path_((fs::path(spec_.dir) / spec_.file).string()),
      settings_((fs::path(spec_.dir) / "batch.json").string(), spec_.settings, spec_.version) {
  std::vector<std::string> outputs = {path_, settings_.path()};
  for (const auto& name : spec_.summaries) outputs.push_back((fs::path(spec_.dir) / name).string());
  checkBatchOutputs(settings_.inputs(), outputs);
  if (!spec_.resume) return;
  if (!fs::exists(path_))
    throw sinks::UserError(fmt::format("simbot: --resume: no table '{}' to resume\n", path_));
  settings_.checkResume(fmt::format("the batch in '{}'", spec_.dir));
  size_t number = 0;
  // A last line cut short by a kill is left out: that run is done again.
  for (const std::string& line : csvRecords(readAll(path_))) {
    CsvRow row;
    try {
      row = parseCsvLine(line);
    } catch (const std::invalid_argument& e) {
      throw sinks::UserError(fmt::format("{}: error: {}\n", where(number + 1), e.what()));
    }
    if (number++ == 0) {
      if (row != spec_.header)
        throw sinks::UserError(
            fmt::format("{}: error: not this batch's table (its header differs)\n", where(1)));
      continue;
    }
    if (row.size() != spec_.header.size())
      throw sinks::UserError(fmt::format("{}: error: {} fields, the header has {}\n", where(number),
                                         row.size(), spec_.header.size()));
    previous_.push_back({number, std::move(row)});
  }
}

RunTable::~RunTable() = default;

std::string RunTable::where(size_t line) const { return fmt::format("{}:{}", path_, line); }

void RunTable::begin() {
  if (rows_) return;
  makeOutputFolder(spec_.dir);
  if (spec_.resume) {
    // The table with its complete rows only, then appended to.
    std::vector<CsvRow> keep;
    for (const auto& row : previous_) keep.push_back(row.fields);
    rewrite(keep);
    return;
  }
  // The old batch's settings and summaries describe a table that is about
  // to go: removed first, so that nothing stale is ever beside the new one.
  settings_.remove();
  for (const auto& name : spec_.summaries) {
    std::error_code ec;
    fs::remove(fs::path(spec_.dir) / name, ec);
  }
  writeFileAtomically(path_, csvRecord(spec_.header));
  settings_.write();
  rows_.emplace(path_);
}

void RunTable::append(const CsvRow& row) {
  if (!rows_) throw std::logic_error("RunTable::append before begin");
  rows_->append(csvRecord(row));
}

void RunTable::rewrite(const std::vector<CsvRow>& rows) {
  std::string text = csvRecord(spec_.header);
  for (const auto& row : rows) text += csvRecord(row);
  rows_.reset();
  writeFileAtomically(path_, text);
  rows_.emplace(path_);
}

nlohmann::json inputContents(const std::vector<std::string>& paths) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& path : paths) out[path] = files::fingerprint(path);
  return out;
}

std::string settingsChange(const nlohmann::json& earlier, const nlohmann::json& now) {
  if (!earlier.is_object() || !now.is_object()) return "was written by another kind of batch";
  // Another simbot may run the same settings differently: said first.
  if (const auto version = now.find("simbot"); version != now.end()) {
    const auto was = earlier.find("simbot");
    if (was == earlier.end())
      return fmt::format("was run by a simbot that did not record its version, not {}",
                         version->get<std::string>());
    if (*was != *version)
      return fmt::format("was run by {}, not {}",
                         was->is_string() ? was->get<std::string>() : sinks::dumpJson(*was),
                         version->get<std::string>());
  }
  for (const auto& [key, value] : now.items()) {
    const auto was = earlier.find(key);
    if (was == earlier.end()) return fmt::format("was run before '{}' was recorded", key);
    if (*was == value) continue;
    if (key == "contents" && was->is_object() && value.is_object())
      for (const auto& [file, print] : value.items())
        if (!was->contains(file) || (*was)[file] != print)
          return was->contains(file)
                     ? fmt::format("was run with another '{}' (its contents changed)", file)
                     : fmt::format("was run without '{}'", file);
    return fmt::format("was run with {} {}, not {}", key, sinks::dumpJson(*was),
                       sinks::dumpJson(value));
  }
  return "was run with other settings";
}

// ---- signals

namespace {

std::atomic<bool> gStopRequested{false};
std::atomic<int> gStopSignal{0};
struct sigaction gPreviousInt {
}, gPreviousTerm{};

extern "C" void onStopSignal(int sig) {
  gStopSignal.store(sig);
  gStopRequested.store(true);
}

}  // namespace

StopOnSignals::StopOnSignals() {
  gStopRequested.store(false);
  gStopSignal.store(0);
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &gPreviousInt);
  sigaction(SIGTERM, &action, &gPreviousTerm);
}

StopOnSignals::~StopOnSignals() {
  sigaction(SIGINT, &gPreviousInt, nullptr);
  sigaction(SIGTERM, &gPreviousTerm, nullptr);
}

const std::atomic<bool>& StopOnSignals::requested() const { return gStopRequested; }
int StopOnSignals::signal() const { return gStopSignal.load(); }

}  // namespace simbot::batch
