#pragma once
/// Each sub-command lives in its own cmd_*.cpp and registers itself here. A registration adds the
/// sub-command and its options to `app` and sets its callback; the callback throws InputError for
/// bad input (exit 1) and returns normally on success (exit 0).
#include <CLI/CLI.hpp>

namespace fieldpath::app {

struct GlobalOptions {
  bool quiet = false;  ///< silence progress lines on stderr
};

void addToolCommand(CLI::App& app, const GlobalOptions& global);
void addSimulateCommand(CLI::App& app, const GlobalOptions& global);
void addFieldCommand(CLI::App& app, const GlobalOptions& global);
void addGenerateCommand(CLI::App& app, const GlobalOptions& global);
void addCheckCommand(CLI::App& app, const GlobalOptions& global);
void addStudyCommand(CLI::App& app, const GlobalOptions& global);

}  // namespace fieldpath::app
