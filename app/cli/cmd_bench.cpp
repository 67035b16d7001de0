// cmd_bench.cpp — `caustica bench`: run time against error for each estimator.
#include "cli/commands.h"
#include "core/error.h"

namespace caustica::cli {

int cmdBench(const std::vector<std::string>&) { throw Error("the benchmark is not built yet"); }

}  // namespace caustica::cli
