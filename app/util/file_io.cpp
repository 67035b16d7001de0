// file_io.cpp — whole-file reading with clear errors (see file_io.h).
#include "util/file_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace caustica {

std::vector<unsigned char> readFileBytes(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw Error(path + ": cannot open: file not found");
  if (std::filesystem::is_directory(status)) throw Error(path + ": cannot open: it is a directory");
  if (!std::filesystem::is_regular_file(status)) throw Error(path + ": cannot open: not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open: " + std::strerror(errno));
  std::vector<unsigned char> bytes;
  char block[65536];
  while (in.read(block, sizeof block) || in.gcount() > 0) {
    bytes.insert(bytes.end(), block, block + in.gcount());
    if (bytes.size() > 0xffff0000u) throw Error(path + ": the file is too large (4 GiB or more)");
  }
  if (in.bad()) throw Error(path + ": read error: " + std::strerror(errno));
  return bytes;
}

std::string readFileText(const std::string& path) {
  std::vector<unsigned char> bytes = readFileBytes(path);
  return std::string(bytes.begin(), bytes.end());
}

void writeFileAtomically(const std::string& path, const std::string& tmpSuffix,
                         const std::function<void(const std::string& tmp)>& write) {
  const std::string tmp = path + tmpSuffix;
  try {
    write(tmp);
    const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
      const int e = errno;
      if (fd >= 0) ::close(fd);
      throw Error(tmp + ": cannot flush to disk (" + std::strerror(e) + ")");
    }
    ::close(fd);
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw Error(path + ": cannot rename the temporary file into place (" + std::strerror(errno) + ")");
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
  // Make the rename itself durable.
  const std::string dir = std::filesystem::path(path).parent_path().string();
  const int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace caustica
