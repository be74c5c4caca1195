#include "rcm/io/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace rcm {

StatusOr<std::string> ReadFileToString(const std::string& path) {
  struct stat info;
  if (stat(path.c_str(), &info) != 0) {
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  if (S_ISDIR(info.st_mode)) {
    return Status::Error(path + ": is a directory, expected a file");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream) {
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  std::ostringstream contents;
  contents << stream.rdbuf();
  if (stream.bad()) {
    return Status::Error(path + ": read failed");
  }
  return contents.str();
}

Status WriteFileAtomically(const std::string& path,
                           const std::string& contents) {
  const std::string temporary =
      path + ".tmp." + std::to_string(static_cast<long>(getpid()));
  FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    return Status::Error(path + ": cannot write: " + std::strerror(errno));
  }
  const size_t written = std::fwrite(contents.data(), 1, contents.size(), file);
  const bool flushed = std::fflush(file) == 0 && fsync(fileno(file)) == 0;
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != contents.size() || !flushed || !closed) {
    std::remove(temporary.c_str());
    return Status::Error(path +
                         ": write failed: " + std::strerror(write_errno));
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary.c_str());
    return Status::Error(path +
                         ": cannot write: " + std::strerror(rename_errno));
  }
  return Status::Ok();
}

}  // namespace rcm
