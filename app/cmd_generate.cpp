#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addGenerateCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("generate", "(not yet implemented)");
  cmd->callback([] { throw InputError("'generate' is not implemented yet"); });
}

}  // namespace fieldpath::app
