// bench_runner.h — `caustica bench` once its options are parsed: per scene the settings, the
// reference, the measured progressive runs with their checkpoints, then the report.
#pragma once
#include "cli/cli_common.h"

namespace caustica::cli {

// Benchmarks every scene the options name (default: every bundled scene); the options are those
// cmd_bench.cpp declares. Writes the CSVs, plots and summary.md under --out; returns the exit status.
int runBench(const Options& opts);

}  // namespace caustica::cli
