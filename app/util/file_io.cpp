// file_io.cpp — whole-file reading with clear errors (see file_io.h).
#include "util/file_io.h"

#include <cerrno>
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

}  // namespace caustica
