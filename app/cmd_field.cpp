#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addFieldCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("field", "(not yet implemented)");
  cmd->callback([] { throw InputError("'field' is not implemented yet"); });
}

}  // namespace fieldpath::app
