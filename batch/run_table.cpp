#include "batch/run_table.h"

#include <fmt/format.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

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
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f)
    throw sinks::UserError(
        fmt::format("simbot: cannot write '{}': {}\n", tmp, std::strerror(errno)));
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool flushed = std::fflush(f) == 0;
  const int error = errno;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    std::remove(tmp.c_str());
    throw sinks::UserError(fmt::format("simbot: writing '{}': {}\n", path, std::strerror(error)));
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec)
    throw sinks::UserError(fmt::format("simbot: cannot write '{}': {}\n", path, ec.message()));
}

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

RunTable::RunTable(const std::string& dir, const std::string& file, const CsvRow& header,
                   const nlohmann::json& settings, bool resume)
    : dir_(dir), path_((fs::path(dir) / file).string()), header_(header) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw sinks::UserError(fmt::format("simbot: cannot use '{}' for the outputs: {}\n", dir,
                                       ec ? ec.message() : "not a directory"));
  const std::string settingsPath = (fs::path(dir) / "batch.json").string();
  if (resume) {
    if (!fs::exists(path_))
      throw sinks::UserError(fmt::format("simbot: --resume: no table '{}' to resume\n", path_));
    nlohmann::json earlier;
    try {
      earlier = nlohmann::json::parse(readAll(settingsPath));
    } catch (const std::exception&) {
      throw sinks::UserError(
          fmt::format("simbot: --resume: '{}' is missing or unreadable\n", settingsPath));
    }
    if (earlier != settings)
      throw sinks::UserError(fmt::format(
          "simbot: --resume: the batch in '{}' was run with other settings ({}); run it again "
          "with those, or choose another --out\n",
          dir, sinks::dumpJson(earlier)));
    size_t number = 0;
    // A last line cut short by a kill is left out: that run is done again.
    for (const std::string& line : csvRecords(readAll(path_))) {
      CsvRow row;
      try {
        row = parseCsvLine(line);
      } catch (const std::invalid_argument& e) {
        throw sinks::UserError(fmt::format("{}:{}: error: {}\n", path_, number + 1, e.what()));
      }
      if (number++ == 0) {
        if (row != header)
          throw sinks::UserError(
              fmt::format("{}:1: error: not this batch's table (its header differs)\n", path_));
        continue;
      }
      if (row.size() != header.size())
        throw sinks::UserError(fmt::format("{}:{}: error: {} fields, the header has {}\n", path_,
                                           number, row.size(), header.size()));
      previous_.push_back(std::move(row));
    }
    // Rewrite the table with the complete rows only, then append to it.
    std::vector<CsvRow> keep = previous_;
    rewrite(keep);
  } else {
    writeFileAtomically(settingsPath, sinks::dumpJson(settings, 2) + "\n");
    writeFileAtomically(path_, csvRecord(header));
  }
  file_ = std::fopen(path_.c_str(), "ab");
  if (!file_)
    throw sinks::UserError(
        fmt::format("simbot: cannot write '{}': {}\n", path_, std::strerror(errno)));
}

RunTable::~RunTable() {
  if (file_) std::fclose(file_);
}

void RunTable::append(const CsvRow& row) {
  const std::string line = csvRecord(row);
  std::lock_guard lock(mutex_);
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size() || std::fflush(file_) != 0)
    throw sinks::UserError(fmt::format("simbot: writing '{}': {}\n", path_, std::strerror(errno)));
}

void RunTable::rewrite(const std::vector<CsvRow>& rows) {
  std::string text = csvRecord(header_);
  for (const auto& row : rows) text += csvRecord(row);
  std::lock_guard lock(mutex_);
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  writeFileAtomically(path_, text);
  file_ = std::fopen(path_.c_str(), "ab");
  if (!file_)
    throw sinks::UserError(
        fmt::format("simbot: cannot write '{}': {}\n", path_, std::strerror(errno)));
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
