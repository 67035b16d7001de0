// commands.h — the subcommands of the caustica program. Each takes the arguments after its name
// and returns the exit status; errors are thrown as caustica::Error and reported by main.
#pragma once
#include <string>
#include <vector>

namespace caustica::cli {

int cmdRender(const std::vector<std::string>& args);
int cmdInfo(const std::vector<std::string>& args);
int cmdView(const std::vector<std::string>& args);
int cmdBench(const std::vector<std::string>& args);
int cmdCompare(const std::vector<std::string>& args);
int cmdMerge(const std::vector<std::string>& args);

}  // namespace caustica::cli
