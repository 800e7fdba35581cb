// Inputs: opened without waiting, regular files only, within their limit
// (files.h).
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "files/files.h"

namespace simbot::files {

namespace {

// The descriptor of a checked input; Error with the reason otherwise.
int openChecked(const std::string& path, std::uint64_t maxBytes) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a
  // writer. It is refused below, like every file that is not regular.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(errno == ENOENT ? "no such file" : std::strerror(errno));
  struct stat st {};
  const char* problem = nullptr;
  if (::fstat(fd, &st) != 0)
    problem = std::strerror(errno);
  else if (S_ISDIR(st.st_mode))
    problem = "it is a directory";
  else if (!S_ISREG(st.st_mode))
    problem = "not a regular file";
  if (problem) {
    ::close(fd);
    throw Error(problem);
  }
  if (static_cast<std::uint64_t>(st.st_size) > maxBytes) {
    ::close(fd);
    throw Error(fmt::format("{} bytes is more than the limit of {}", st.st_size, maxBytes));
  }
  // Reads block again (a regular file never waits; this keeps the stream
  // ordinary).
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}

}  // namespace

std::string readInput(const std::string& path, std::uint64_t maxBytes) {
  const int fd = openChecked(path, maxBytes);
  std::string text;
  char buffer[65536];
  // Bounded even where the size said nothing (a file in /proc reports 0).
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      throw Error(std::strerror(error));
    }
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > maxBytes) {
      ::close(fd);
      throw Error(fmt::format("more than the limit of {} bytes", maxBytes));
    }
    text.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

std::string fingerprint(const std::string& path) {
  std::string text;
  try {
    text = readInput(path, kMaxConfigBytes * 16);
  } catch (const Error& e) {
    return std::string("unreadable: ") + e.what();
  }
  std::uint64_t hash = 0xcbf29ce484222325u;  // FNV-1a's offset basis and prime
  for (const char c : text) hash = (hash ^ static_cast<unsigned char>(c)) * 0x100000001b3u;
  return fmt::format("fnv1a64:{:016x}", hash);
}

Input::Input(const std::string& path, std::uint64_t maxBytes) {
  const int fd = openChecked(path, maxBytes);
  file_ = ::fdopen(fd, "rb");
  if (!file_) {
    const int error = errno;
    ::close(fd);
    throw Error(std::strerror(error));
  }
}

Input::~Input() {
  if (file_) std::fclose(file_);
}

bool Input::readLine(std::string& line, bool& whole, std::size_t maxBytes) {
  constexpr std::size_t kChunk = 65536;
  line.clear();
  while (true) {
    const char* start = buffer_.data() + at_;
    const std::size_t left = buffer_.size() - at_;
    const void* newline = std::memchr(start, '\n', left);
    const std::size_t take =
        newline ? static_cast<std::size_t>(static_cast<const char*>(newline) - start) : left;
    if (line.size() + take > maxBytes)
      throw LineTooLong(fmt::format("a line of more than {} bytes", maxBytes));
    line.append(start, take);
    if (newline) {
      at_ += take + 1;
      whole = true;
      return true;
    }
    // The buffer is used up: the next chunk.
    buffer_.resize(kChunk);
    at_ = 0;
    const std::size_t n = std::fread(buffer_.data(), 1, kChunk, file_);
    buffer_.resize(n);
    if (n == 0) {
      if (std::ferror(file_)) throw Error(std::strerror(errno));
      whole = false;
      return !line.empty();
    }
  }
}

}  // namespace simbot::files
