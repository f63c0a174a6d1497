/// fieldpath: collision-free 5-axis ball-end paths through a repulsive field, and their proof.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iterator>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "commands.h"
#include "errors.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/common/output_signals.h"
#include "fieldpath/zbuffer/simulator.h"
#include "progress.h"
#include "scene.h"

#ifndef FIELDPATH_VERSION
#define FIELDPATH_VERSION "unknown"
#endif

namespace {

/// FIELDPATH_T0=$(date +%s%N) fieldpath ...: when main() starts and ends, in ms after that
/// instant, on stderr (bench/zbuffer/process.sh: what a process pays before and after its work).
struct StartupTrace {
  long long t0_ns = 0;
  StartupTrace() {
    if (const char* t0 = std::getenv("FIELDPATH_T0")) t0_ns = std::atoll(t0);
    say("main() entered");
  }
  ~StartupTrace() { say("main() returns"); }
  void say(const char* what) const {
    if (t0_ns <= 0) return;
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    const long long ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now).count();
    std::fprintf(stderr, "trace: %s %.1f ms after FIELDPATH_T0\n", what, double(ns - t0_ns) / 1e6);
  }
};

/// An error as one line: control characters (a newline or a NUL in a YAML parser's message, a
/// file name with a tab) are written as \xNN, so that "one clear line" holds for any input.
std::string oneLine(const char* what) {
  std::string out;
  const char* end = what + std::strlen(what);
  while (end > what && static_cast<unsigned char>(end[-1]) <= 0x20) --end;  // trailing newlines
  for (const char* c = what; c < end; ++c) {
    const auto byte = static_cast<unsigned char>(*c);
    if (byte < 0x20 || byte == 0x7f) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", byte);
      out += hex;
    } else {
      out += *c;
    }
  }
  return out;
}

/// What a command prints is its result (`field probe`'s values, `--help`): a full disk,
/// `ulimit -f` or a closed stdout lost it, read as success. Says so; true when it was lost.
bool standardOutputLost() {
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  const int error = errno;
  if (flushed && !std::ferror(stdout)) return false;
  fieldpath::app::endProgressLine();
  std::fprintf(stderr, "fieldpath: error: cannot write the standard output%s%s\n",
               error != 0 ? ": " : "", error != 0 ? std::strerror(error) : "");
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fieldpath::app;
  const StartupTrace trace;
  fieldpath::common::installTemporaryCleanupOnSignals();  // no partial outputs on Ctrl-C
  fieldpath::common::guardInputs();  // no output written over a file the run read
  CLI::App app{
      "fieldpath: collision-free 5-axis ball-end milling paths (repulsive field), "
      "clearance check and Z-buffer machining simulation"};
  app.set_version_flag("--version", std::string("fieldpath ") + FIELDPATH_VERSION);
  app.require_subcommand(1);
  GlobalOptions global;
  app.add_flag("--quiet", global.quiet,
               "No progress lines on stderr (before or after the command)");
  // Options a sub-command does not know fall through to this level, so `fieldpath simulate ...
  // --quiet` works as well as `fieldpath --quiet simulate ...`. Sub-commands inherit the setting.
  app.fallthrough();
  std::string max_memory;
  app.add_option("--max-memory", max_memory,
                 "Refuse work whose estimated memory exceeds this (e.g. 512M, 4G; default: the "
                 "machine's available memory)");
  int threads = 0;
  app.add_option("--threads", threads,
                 "Use at most N threads (default: one a core; the outputs are the same whatever "
                 "the number)")
      ->check(CLI::Range(1, 4096));
  // Held for the whole run: TBB (the steering, the checks, the field) and OpenMP (the Z-buffer).
  std::optional<tbb::global_control> thread_limit;
  app.parse_complete_callback([&max_memory, &global, &threads, &thread_limit] {
    fieldpath::app::progressQuiet() = global.quiet;
    if (!max_memory.empty()) fieldpath::common::limitMemory(max_memory, "--max-memory");
    if (threads > 0) {
      thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                           static_cast<std::size_t>(threads));
      fieldpath::zbuffer::limitCpuThreads(threads);
    }
  });

  addToolCommand(app, global);
  addSimulateCommand(app, global);
  addFieldCommand(app, global);
  addGenerateCommand(app, global);
  addCheckCommand(app, global);
  addStudyCommand(app, global);
  addViewCommand(app, global);
  addConvertCommand(app, global);

  // An empty argument is no value: `--part ""` or `--region ""` read as the option not given
  // (the default silently taken: a helper's); `--opt=` the same.
  // A name option followed by an option (`--out --quiet`) made a folder named `--quiet`.
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i], before = argv[i - 1];
    static const char* const kNameOptions[] = {"--out",   "--path",   "--check",      "--surface",
                                               "--part",  "--points", "--save-field", "--tool",
                                               "--shape", "--holder"};
    if (arg.rfind("--", 0) != 0 || std::none_of(std::begin(kNameOptions), std::end(kNameOptions),
                                                [&before](const char* o) { return before == o; }))
      continue;
    std::fprintf(stderr,
                 "fieldpath: error: %s: '%s' is an option, not a name (a file of that name: "
                 "%s=./%s)\n",
                 before.c_str(), oneLine(arg.c_str()).c_str(), before.c_str(),
                 oneLine(arg.c_str()).c_str());
    return 1;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool empty_after_equals = arg.size() > 2 && arg.rfind("--", 0) == 0 && arg.back() == '=';
    if (!arg.empty() && !empty_after_equals) continue;
    const std::string before = i > 1 ? argv[i - 1] : "";
    const std::string where =
        empty_after_equals ? arg.substr(0, arg.size() - 1) + ": an empty value"
        : before.rfind("-", 0) == 0
            ? before + ": an empty value"
            : "an empty argument after '" + (i > 1 ? before : "fieldpath") + "'";
    std::fprintf(stderr, "fieldpath: error: %s: give one, or leave it out (see --help)\n",
                 oneLine(where.c_str()).c_str());
    return 1;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {  // --help, --version
      const int code = app.exit(e);
      return standardOutputLost() ? 1 : code;
    }
    // `fieldpath frobnicate`, `fieldpath field prob`: CLI11 says "a subcommand is required",
    // which hides the typo. The words are walked down the commands; the first that is none
    // where one is required is named.
    const CLI::App* at = &app;
    std::string chain = "fieldpath";
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (at == &app && (arg == "--max-memory" || arg == "--threads")) {
        ++i;  // its value
        continue;
      }
      if (arg.empty() || arg[0] == '-') continue;
      const std::vector<const CLI::App*> subs = at->get_subcommands({});
      const auto sub = std::find_if(subs.begin(), subs.end(),
                                    [&arg](const CLI::App* c) { return c->get_name() == arg; });
      if (sub != subs.end()) {
        at = *sub;
        chain += " " + arg;
        continue;
      }
      if (at->get_require_subcommand_min() > 0 && !subs.empty()) {
        std::string known;
        for (const CLI::App* c : subs) known += (known.empty() ? "" : ", ") + c->get_name();
        fieldpath::app::endProgressLine();
        std::fprintf(stderr,
                     "fieldpath: error: unknown command '%s' (%s takes: %s; see --help)\n",
                     oneLine(arg.c_str()).c_str(), chain.c_str(), known.c_str());
        return 1;
      }
      break;  // the command's own arguments
    }
    if (at->get_require_subcommand_min() > 0 && at->get_subcommands().empty()) {
      std::string known;  // `fieldpath` or `fieldpath field` alone
      for (const CLI::App* c : at->get_subcommands({}))
        known += (known.empty() ? "" : ", ") + c->get_name();
      fieldpath::app::endProgressLine();
      std::fprintf(stderr, "fieldpath: error: %s needs a command: %s (see --help)\n",
                   chain.c_str(), known.c_str());
      return 1;
    }
    // A usage error is bad input: one line, exit 1 (CLI11's own report adds a second line).
    // A file named with a leading '-' where a positional is missing ("scene is required", not
    // "--path is required": `./` helps the first only) reads as an option: said, with the way
    // round it. Not for an option's value (`--path -in.cl` is read as a path; a flag such as
    // --fail-unsafe takes none) nor after `--` (positional there).
    std::string dash_file;
    const std::string what = e.what();
    const std::size_t required = what.find(" is required");
    if (required != std::string::npos && required > 0 && what[0] != '-')
      for (int i = 1; i < argc && dash_file.empty(); ++i) {
        std::error_code ec;
        const std::string arg = argv[i], before = i > 1 ? argv[i - 1] : "";
        if (arg == "--") break;
        const CLI::Option* option =
            before.rfind("--", 0) == 0 && before.find('=') == std::string::npos
                ? at->get_option_no_throw(before)
                : nullptr;
        if (!option && before.rfind("--", 0) == 0) option = app.get_option_no_throw(before);
        const bool a_value = option && option->get_expected_min() > 0;
        if (arg.size() > 1 && arg[0] == '-' && !a_value &&
            std::filesystem::is_regular_file(arg, ec))
          dash_file = arg;
      }
    fieldpath::app::endProgressLine();
    std::fprintf(stderr, "fieldpath: error: %s%s (see --help)\n", oneLine(e.what()).c_str(),
                 dash_file.empty()
                     ? ""
                     : ("; '" + oneLine(dash_file.c_str()) + "' reads as an option: name it ./" +
                        oneLine(dash_file.c_str()))
                           .c_str());
    return 1;
  } catch (const InputError& e) {
    fieldpath::common::removeWrittenOutputs();  // a failed run leaves no partial set of outputs
    fieldpath::app::endProgressLine();
    std::fprintf(stderr, "fieldpath: error: %s\n",
                 oneLine(placeSceneKey(e.what()).c_str()).c_str());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // Reading or writing a path the user gave (an --out that is a file, a directory without
    // permission, a full disk): their environment, not our bug.
    fieldpath::common::removeWrittenOutputs();
    fieldpath::app::endProgressLine();
    std::fprintf(stderr, "fieldpath: error: %s\n", oneLine(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    // The machine's memory or the process's limit (`ulimit -v`): their environment, not a bug.
    fieldpath::common::removeWrittenOutputs();
    const std::size_t headroom = fieldpath::common::processHeadroomBytes();
    const std::string limit = headroom == SIZE_MAX
                                  ? std::string()
                                  : ", or the process's ulimit -v / -d (" +
                                        fieldpath::common::formatBytes(double(headroom)) + " left)";
    fieldpath::app::endProgressLine();
    std::fprintf(stderr,
                 "fieldpath: error: out of memory (the machine's%s; --max-memory refuses large "
                 "work before it starts)\n",
                 limit.c_str());
    return 1;
  } catch (const std::system_error& e) {
    // A thread or a file the system would not give (`ulimit -u`, `ulimit -v` too small for a
    // thread's stack): the environment again.
    fieldpath::common::removeWrittenOutputs();
    fieldpath::app::endProgressLine();
    std::fprintf(stderr, "fieldpath: error: the system refused a resource: %s\n",
                 oneLine(e.what()).c_str());
    return 1;
  } catch (const std::exception& e) {
    fieldpath::common::removeWrittenOutputs();
    fieldpath::app::endProgressLine();
    // TBB says a thread it could not start in a plain runtime_error (`ulimit -u`, a container's
    // pids limit: read as a bug, exit 2, by an environment sweep): the environment, exit 1.
    if (std::string_view(e.what()).starts_with("pthread_create")) {
      std::fprintf(stderr,
                   "fieldpath: error: the system refused a thread (%s): a process or thread "
                   "limit (ulimit -u, a container's pids limit)?\n",
                   oneLine(e.what()).c_str());
      return 1;
    }
    std::fprintf(stderr, "fieldpath: internal error: %s\n", oneLine(e.what()).c_str());
    return 2;
  }
  if (standardOutputLost()) {
    fieldpath::common::removeWrittenOutputs();
    return 1;
  }
  fieldpath::common::commitOutputs();  // done: a late signal takes nothing away
  return fieldpath::app::verdictExitCode();
}
