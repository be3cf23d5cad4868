// Output files that are never left half-written: content goes to a temporary
// name in the same directory, is flushed to disk, and is renamed over the
// final name (rename(2) is atomic within a file system).
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "cli/cli.h"

namespace odemag::cli {

namespace {

std::string system_error(const std::string& what, const std::string& path) {
  return what + " " + path + ": " + std::strerror(errno);
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string temporary = path + ".tmp-" + std::to_string(getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(system_error("cannot create", temporary));
  size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string message = system_error("cannot write", temporary);
      ::close(fd);
      ::unlink(temporary.c_str());
      throw std::runtime_error(message);
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string message = system_error("cannot write", temporary);
    ::unlink(temporary.c_str());
    throw std::runtime_error(message);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string message = system_error("cannot rename to", path);
    ::unlink(temporary.c_str());
    throw std::runtime_error(message);
  }
}

StreamedFile::StreamedFile(std::string path) : path_(std::move(path)), partial_(path_ + ".partial") {
  file_ = std::fopen(partial_.c_str(), "w");
  if (!file_) throw std::runtime_error(system_error("cannot create", partial_));
}

StreamedFile::~StreamedFile() {
  if (file_) std::fclose(file_);  // unfinished: the .partial file stays as evidence
}

void StreamedFile::append(const std::string& text) {
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size())
    throw std::runtime_error(system_error("cannot write", partial_));
}

void StreamedFile::finish() {
  const bool flushed = std::fflush(file_) == 0 && ::fsync(fileno(file_)) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) throw std::runtime_error(system_error("cannot write", partial_));
  if (std::rename(partial_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error(system_error("cannot rename to", path_));
}

}  // namespace odemag::cli
