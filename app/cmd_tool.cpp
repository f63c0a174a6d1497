#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addToolCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("tool", "(not yet implemented)");
  cmd->callback([] { throw InputError("'tool' is not implemented yet"); });
}

}  // namespace fieldpath::app
