#pragma once
/// Running the built `fieldpath` as a child process the tests can signal or pin to cores, and
/// reading what it left: the reliability tests' helpers (test_reliability.cpp,
/// test_deterministic.cpp). FIELDPATH_EXE and FIELDPATH_SOURCE_DIR are the target's definitions.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "run_fieldpath.h"

namespace fieldpath::test::reliability {

namespace fs = std::filesystem;
// With the helpers, for the tests that take them with `using namespace`.
using test::slurp;
using test::TempDir;

inline const fs::path kImpeller = fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// Every file under `dir` (relative names, sorted).
inline std::vector<std::string> filesUnder(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) names.push_back(fs::relative(e.path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

inline bool isTemporary(const std::string& name) {
  return fs::path(name).filename().string().find(".tmp-") != std::string::npos;
}

/// Starts `fieldpath --quiet ARGS...` in `dir` (output to files there); returns its pid.
/// `cpus` non-empty: run under `taskset -c cpus` (TBB and OpenMP then use those cores only).
inline pid_t start(const TempDir& dir, std::vector<std::string> args,
                   const std::string& cpus = {}) {
  args.insert(args.begin(), {FIELDPATH_EXE, "--quiet"});
  if (!cpus.empty()) args.insert(args.begin(), {"taskset", "-c", cpus});
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.path().c_str()) != 0) _exit(126);
    freopen("stdout.txt", "w", stdout);
    freopen("stderr.txt", "w", stderr);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// Waits for `pid`; returns the exit code, or 128 + the signal that ended it.
inline int finish(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// Runs a command to completion; returns its exit code.
inline int run(const TempDir& dir, const std::vector<std::string>& args,
               const std::string& cpus = {}) {
  return finish(start(dir, args, cpus));
}

}  // namespace fieldpath::test::reliability
