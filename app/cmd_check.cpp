#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addCheckCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("check", "(not yet implemented)");
  cmd->callback([] { throw InputError("'check' is not implemented yet"); });
}

}  // namespace fieldpath::app
