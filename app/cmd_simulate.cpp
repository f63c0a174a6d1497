#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addSimulateCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("simulate", "(not yet implemented)");
  cmd->callback([] { throw InputError("'simulate' is not implemented yet"); });
}

}  // namespace fieldpath::app
