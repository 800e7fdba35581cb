// Outputs that replace their file only when complete, the check that no
// output is an input, and the signal handler that removes temporary files
// (files.h).
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <filesystem>

#include "files/files.h"

namespace simbot::files {

namespace fs = std::filesystem;

namespace {

// The temporary files a signal handler must remove: a fixed table, so that
// the handler reads no memory that may be in the middle of a change. A
// slot is claimed, its name written, and only then marked ready.
constexpr std::size_t kSlots = 64;
std::array<std::array<char, PATH_MAX>, kSlots> gNames{};
std::array<std::atomic<bool>, kSlots> gClaimed{};
std::array<std::atomic<bool>, kSlots> gReady{};

int registerTemporary(const std::string& name) {
  if (name.size() >= PATH_MAX) return -1;
  for (std::size_t s = 0; s < kSlots; ++s) {
    bool expected = false;
    if (!gClaimed[s].compare_exchange_strong(expected, true)) continue;
    std::memcpy(gNames[s].data(), name.c_str(), name.size() + 1);
    gReady[s].store(true);
    return static_cast<int>(s);
  }
  return -1;  // more outputs at once than slots: this one may be left behind
}

void unregisterTemporary(int slot) {
  if (slot < 0) return;
  gReady[static_cast<std::size_t>(slot)].store(false);
  gClaimed[static_cast<std::size_t>(slot)].store(false);
}

extern "C" void onFatalSignal(int sig) {
  for (std::size_t s = 0; s < kSlots; ++s)
    if (gReady[s].load()) ::unlink(gNames[s].data());
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

mode_t processUmask() {
  // Read from /proc (Linux 4.7 and later), not by setting it: setting it,
  // even for an instant, would make another thread's files (the Python
  // module's caller's) with the wrong mode.
  static const mode_t mask = [] {
    std::FILE* status = std::fopen("/proc/self/status", "r");
    unsigned value = 022;
    char line[256];
    while (status && std::fgets(line, sizeof line, status))
      if (std::sscanf(line, "Umask: %o", &value) == 1) break;
    if (status) std::fclose(status);
    return static_cast<mode_t>(value);
  }();
  return mask;
}

// What a name refers to: an existing file by device and inode; a file not
// there yet by its absolute, normalised name.
struct Identity {
  bool exists = false;
  bool regular = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string name;
  bool operator==(const Identity& o) const {
    return exists == o.exists && (exists ? device == o.device && inode == o.inode : name == o.name);
  }
};

Identity identify(const std::string& path) {
  Identity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.regular = S_ISREG(st.st_mode);
    id.device = st.st_dev;
    id.inode = st.st_ino;
  } else {
    std::error_code ec;
    id.name = fs::weakly_canonical(fs::absolute(path, ec), ec).string();
    if (ec) id.name = path;
  }
  return id;
}

}  // namespace

void checkDistinct(const std::vector<Named>& inputs, const std::vector<Named>& outputs) {
  std::vector<Identity> outs;
  for (const auto& o : outputs) outs.push_back(identify(o.path));
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    // Devices (/dev/null written twice) are nobody's work to lose.
    if (outs[k].exists && !outs[k].regular) continue;
    for (const auto& in : inputs)
      if (identify(in.path) == outs[k])
        throw Error(
            fmt::format("{} '{}' is the same file as {} '{}': an output may not "
                        "overwrite an input",
                        outputs[k].role, outputs[k].path, in.role, in.path));
    for (std::size_t j = 0; j < k; ++j)
      if (outs[j] == outs[k])
        throw Error(fmt::format("{} '{}' and {} '{}' are the same file: each output needs its own",
                                outputs[j].role, outputs[j].path, outputs[k].role,
                                outputs[k].path));
  }
}

Output::Output(const std::string& path) : path_(path) {
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw Error("it is a directory");
  if (exists && !S_ISREG(st.st_mode)) {
    file_ = std::fopen(path.c_str(), "wb");  // a device or a pipe: in place
    if (!file_) throw Error(std::strerror(errno));
    return;
  }
  // A file we could not have opened for writing is not replaced either.
  if (exists && ::access(path.c_str(), W_OK) != 0) throw Error(std::strerror(errno));
  // Through a link, the file it names is replaced, not the link.
  std::error_code ec;
  fs::path target = exists ? fs::canonical(path, ec) : fs::path(path);
  if (ec) target = path;
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::string name = (dir / ("." + target.filename().string() + ".simbot-XXXXXX")).string();
  const int fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd < 0) throw Error(std::strerror(errno));
  temporary_ = name;
  path_ = target.string();
  slot_ = registerTemporary(temporary_);
  ::fchmod(fd, exists ? (st.st_mode & 07777) : (0666 & ~processUmask()));
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    const int error = errno;
    ::close(fd);
    discard();
    throw Error(std::strerror(error));
  }
}

Output::~Output() {
  if (committed_) return;
  if (file_) std::fclose(file_);
  file_ = nullptr;
  discard();
}

void Output::discard() {
  if (temporary_.empty()) return;
  ::unlink(temporary_.c_str());
  unregisterTemporary(slot_);
  slot_ = -1;
  temporary_.clear();
}

void Output::commit() {
  if (committed_) return;
  if (!file_) throw Error("the output was already given up");
  errno = 0;
  const bool flushed = !std::ferror(file_) && std::fflush(file_) == 0;
  // On the disk before the rename: after a power loss, the old file or the
  // whole new one, never an empty one.
  const bool synced = flushed && (temporary_.empty() || ::fsync(::fileno(file_)) == 0);
  int error = errno;
  const bool closed = std::fclose(file_) == 0;
  if (flushed && synced && !closed) error = errno;
  file_ = nullptr;
  if (!flushed || !synced || !closed) {
    discard();
    throw Error(std::strerror(error ? error : EIO));
  }
  if (!temporary_.empty() && ::rename(temporary_.c_str(), path_.c_str()) != 0) {
    // The finished output is kept where it is, and said so.
    error = errno;
    const std::string kept = temporary_;
    unregisterTemporary(slot_);
    slot_ = -1;
    temporary_.clear();
    throw Error(
        fmt::format("{} (the finished output is kept as '{}')", std::strerror(error), kept));
  }
  unregisterTemporary(slot_);
  slot_ = -1;
  temporary_.clear();
  committed_ = true;
}

void writeWhole(const std::string& path, const std::string& text) {
  Output out(path);
  if (std::fwrite(text.data(), 1, text.size(), out.file()) != text.size())
    throw Error(std::strerror(errno));
  out.commit();
}

void removeTemporariesOnSignals() {
  processUmask();
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXFSZ}) {
    struct sigaction previous {};
    ::sigaction(sig, nullptr, &previous);
    if (previous.sa_handler != SIG_DFL) continue;  // ignored (nohup) or taken: left so
    struct sigaction action {};
    action.sa_handler = onFatalSignal;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

}  // namespace simbot::files
