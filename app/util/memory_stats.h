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
// With CAUSTICA_MEM_TRACE set in the environment: prints "mem PHASE: rss R MiB, peak P MiB" to stderr,
// to find which load phase sets the peak (docs/big-scenes.md). Otherwise does nothing.
void memTrace(const char* phase);
// Hands memory that the allocator holds freed back to the kernel (glibc's malloc_trim; nothing elsewhere).
// Called after the big frees of loading (the parser's arrays, the BVH build's records): glibc keeps
// freed heap that is not at the top of the heap, and it would count in the peak of the next phase.
void releaseFreedMemory();

}  // namespace caustica
