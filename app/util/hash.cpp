// hash.cpp — FNV-1a 64 (hash.h).
#include "util/hash.h"

#include <cstdio>

namespace caustica {

std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= p[i];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::uint64_t fnv1a64(const std::string& text, std::uint64_t hash) { return fnv1a64(text.data(), text.size(), hash); }

std::string hex64(std::uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

}  // namespace caustica
