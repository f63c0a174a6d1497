#include "commands.h"
#include "errors.h"

namespace fieldpath::app {

void addStudyCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand("study", "(not yet implemented)");
  cmd->callback([] { throw InputError("'study' is not implemented yet"); });
}

}  // namespace fieldpath::app
