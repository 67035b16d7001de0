// cmd_view.cpp — `caustica view`: interactive progressive preview in a GLFW window.
#include "cli/commands.h"
#include "core/error.h"

namespace caustica::cli {

int cmdView(const std::vector<std::string>&) { throw Error("the viewer is not built yet"); }

}  // namespace caustica::cli
