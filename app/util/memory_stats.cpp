// memory_stats.cpp — VmHWM and VmRSS from /proc/self/status, with getrusage as the fallback.
#include "util/memory_stats.h"

#include <sys/resource.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace caustica {

namespace {
// The value of a "Name:   1234 kB" line of /proc/self/status in bytes, 0 when absent.
std::uint64_t statusKiB(const char* name) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  std::uint64_t kib = 0;
  const std::size_t len = std::strlen(name);
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, name, len) == 0 && line[len] == ':') {
      unsigned long long v = 0;
      if (std::sscanf(line + len + 1, "%llu", &v) == 1) kib = v;
      break;
    }
  std::fclose(f);
  return kib * 1024u;
}
}  // namespace

std::uint64_t hostPeakBytes() {
  if (std::uint64_t b = statusKiB("VmHWM")) return b;
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) == 0) return static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;  // KiB on Linux
  return 0;
}

std::uint64_t hostCurrentBytes() { return statusKiB("VmRSS"); }

void memTrace(const char* phase) {
  static const bool on = std::getenv("CAUSTICA_MEM_TRACE") != nullptr;
  if (!on) return;
  std::fprintf(stderr, "mem %s: rss %.1f MiB, peak %.1f MiB\n", phase, double(hostCurrentBytes()) / 1048576.0,
               double(hostPeakBytes()) / 1048576.0);
}

void releaseFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace caustica
