// memory_stats.h — the process's memory use as the kernel counts it (Linux /proc/self/status), for the
// load figures of `info` and `render` (docs/benchmarks.md, "Big scenes"). No GL.
#pragma once
#include <cstdint>

namespace caustica {

// Peak resident set size of this process so far in bytes (VmHWM; getrusage's ru_maxrss where /proc is
// missing); 0 when neither is available. On a software GL (llvmpipe) GPU buffers count here too.
std::uint64_t hostPeakBytes();
// Resident set size now in bytes (VmRSS); 0 when unknown.
std::uint64_t hostCurrentBytes();

}  // namespace caustica
