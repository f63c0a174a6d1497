#pragma once
/// Outputs are written to a temporary name beside the target and renamed into place, so an
/// interrupted run never leaves a truncated file under the final name (DESIGN.md). The temporaries
/// being written are listed where a SIGINT/SIGTERM handler can remove them
/// (removeTemporariesNow(), installed by the CLI's main()).
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ext/stdio_filebuf.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/input_file.h"

namespace fieldpath::common {

namespace detail {

/// One temporary being written. `state`: 0 free, 1 being claimed, 2 live (path valid), 3 being
/// opened (created) by its writer.
struct TemporarySlot {
  std::atomic<int> state{0};
  char path[4096];
};
inline constexpr int kTemporarySlots = 64;
inline TemporarySlot temporary_slots[kTemporarySlots];

/// Lists `path` for removal on a signal; returns its slot, or -1 when every slot is taken or the
/// name is too long (the file is then still written atomically, just not removed on a signal).

/// The outputs claimed by this run (claimOutputs), for a signal handler: an interrupted run, like
/// a failed one, leaves no earlier run's path.cl behind (a script that runs `timeout 60 fieldpath
/// generate` and then posts out/path.apt would have sent the old path).
inline constexpr int kClaimedSlots = 16;
inline TemporarySlot claimed_slots[kClaimedSlots];

/// Lists `path` in `slots` (n of them); -1 when all are taken or the name is too long.
inline int listInSlots(TemporarySlot* slots, int n, const std::string& path) {
  if (path.size() >= sizeof(TemporarySlot::path)) return -1;
  for (int i = 0; i < n; ++i) {
    int expected = 0;
    if (slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
      slots[i].state.store(2);
      return i;
    }
  }
  return -1;
}

inline int listTemporary(const std::string& path) {
  return listInSlots(temporary_slots, kTemporarySlots, path);
}

inline void unlistTemporary(int slot) {
  if (slot >= 0) temporary_slots[slot].state.store(0);
}

/// Set by the signal handler before it removes the temporaries: a writer about to create its
/// temporary then does not (else one created just after the handler's sweep was left behind: a
/// flaky interrupt test, `.heights.npy.tmp-PID`).
inline std::atomic<int> exiting{0};

/// Brackets the creation of slot `slot`'s file against the handler's sweep (Dekker's pattern on
/// seq_cst atomics: the writer marks the slot, then reads `exiting`; the handler sets `exiting`,
/// then reads the slot; one of them sees the other). Returns only when the file may be created;
/// once the handler has begun, it never returns (the handler ends the process).
inline void beginCreating(int slot) {
  if (slot < 0) return;
  temporary_slots[slot].state.store(3);
  if (!exiting.load()) return;
  temporary_slots[slot].state.store(2);  // nothing created: the handler need not wait
  while (true) ::pause();
}
inline void endCreating(int slot) {
  if (slot >= 0) temporary_slots[slot].state.store(2);
}

/// Unlists the temporary slot when the write ends, however it ends.
struct TemporaryListing {
  int slot;
  ~TemporaryListing() { unlistTemporary(slot); }
};

/// "what FILE: strerror(errno)" for a failed system call on a user's output path.
inline std::string systemReason(int error) {
  return error != 0 ? std::strerror(error) : "unknown error";
}

/// Why a write into `dir` failed: errno's text, or a full device when errno was lost on the way
/// (std::ofstream does not keep it).
inline std::string writeReason(int error, const std::filesystem::path& dir) {
  if (error != 0) return std::strerror(error);
  struct statvfs fs {};
  if (::statvfs(dir.empty() ? "." : dir.c_str(), &fs) == 0 && fs.f_bavail == 0)
    return std::strerror(ENOSPC);
  return "write failed";
}

/// The outputs this process has put in place, for removeWrittenOutputs().
inline std::mutex written_mutex;
inline std::vector<std::filesystem::path> written_outputs;
/// The outputs a command writes on success (claimOutputs): removed on failure wherever they are.
inline std::vector<std::filesystem::path> claimed_outputs;

}  // namespace detail

/// Removes every temporary being written. Async-signal-safe (lock-free atomics and unlink only):
/// call it from a SIGINT/SIGTERM handler before re-raising the signal.
inline void removeTemporariesNow() noexcept {
  detail::exiting.store(1);
  for (auto& slot : detail::temporary_slots) {
    // A writer creating its file: waited for, up to 0.2 s (the handler may be running on the
    // writer's own thread, which then never finishes creating it).
    const struct timespec step { 0, 1'000'000 };
    for (int waited = 0; slot.state.load() == 3 && waited < 200; ++waited)
      ::nanosleep(&step, nullptr);
    if (slot.state.load() >= 2) ::unlink(slot.path);
  }
}

/// Removes the outputs this run claimed (claimOutputs), regular files only (lstat, unlink:
/// async-signal-safe), as a failed run does: for a SIGINT/SIGTERM handler.
inline void removeClaimedOutputsNow() noexcept {
  for (auto& slot : detail::claimed_slots) {
    struct stat info {};
    if (slot.state.load() == 2 && ::lstat(slot.path, &info) == 0 && S_ISREG(info.st_mode) &&
        !isInputNow(slot.path))
      ::unlink(slot.path);
  }
}

namespace detail {
/// The output folders this process holds (lockOutputDirectory): locked once each.
inline std::vector<std::filesystem::path> locked_directories;
/// The folders this run made for its outputs, outermost first: removed again, innermost first,
/// where a failed or interrupted run leaves them empty (a refused run leaves no files).
inline constexpr int kCreatedSlots = 8;
inline TemporarySlot created_directories[kCreatedSlots];
}  // namespace detail

/// Removes the output folder this run made (lockOutputDirectory) if it is empty: rmdir only,
/// async-signal-safe.
inline void removeCreatedDirectoryNow() noexcept {
  for (int i = detail::kCreatedSlots - 1; i >= 0; --i)
    if (detail::created_directories[i].state.load() == 2)
      ::rmdir(detail::created_directories[i].path);
}

/// Makes `dir` (and its parents) a directory for outputs. Throws InputError (one line naming the
/// path) when it exists as something else or cannot be created (permissions, read-only file
/// system) — a user's mistake, never an internal error.
inline void createOutputDirectory(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) return;
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  if (fs::exists(dir, ec)) throw InputError(dir.string() + ": exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir.string() + ": cannot create the directory: " + ec.message());
}

/// Checks, before any work, that `dir` can become an output directory: it is a writable
/// directory, or it does not exist and its nearest existing parent is a writable directory.
/// Creates nothing (a refused run leaves no files). Throws InputError "OPTION DIR: why".
inline void checkOutputDirectory(const std::filesystem::path& dir, const std::string& option) {
  namespace fs = std::filesystem;
  const std::string name = option.empty() ? dir.string() : option + " " + dir.string();
  if (dir.empty()) throw InputError(name + ": empty directory name");
  std::error_code ec;
  fs::path at = fs::absolute(dir, ec);
  if (ec) throw InputError(name + ": " + ec.message());
  // The nearest existing ancestor (the path itself if it exists).
  while (!fs::exists(fs::symlink_status(at, ec)) && at.has_parent_path() && at != at.parent_path())
    at = at.parent_path();
  if (at == fs::absolute(dir, ec)) {
    if (!fs::is_directory(at, ec)) throw InputError(name + ": exists and is not a directory");
  } else if (!fs::is_directory(at, ec)) {
    throw InputError(name + ": cannot be created: " + at.string() + " is not a directory");
  }
  if (::access(at.c_str(), W_OK | X_OK) != 0)
    throw InputError(name + ": cannot write in " + at.string() + ": " +
                     detail::systemReason(errno));
  // access() says yes to root everywhere and knows nothing of /proc or read-only mounts: where
  // the directory does not exist yet, make it and take it away again (nothing is left).
  if (at != fs::absolute(dir, ec)) {
    // The first missing component below the existing ancestor.
    const fs::path first = at / *fs::absolute(dir, ec).lexically_relative(at).begin();
    if (::mkdir(first.c_str(), 0777) != 0)
      throw InputError(name + ": cannot be created: " + detail::systemReason(errno));
    ::rmdir(first.c_str());
  }
}

/// Checks that an output file `file` can be written (its directory can exist, the name is not a
/// directory). Throws InputError "OPTION FILE: why".
inline void checkOutputFile(const std::filesystem::path& file, const std::string& option) {
  namespace fs = std::filesystem;
  const std::string name = option.empty() ? file.string() : option + " " + file.string();
  std::error_code ec;
  if (file.empty() || !file.has_filename()) throw InputError(name + ": expected a file name");
  if (fs::is_directory(file, ec)) throw InputError(name + ": is a directory, expected a file name");
  const fs::path parent = file.has_parent_path() ? file.parent_path() : fs::path(".");
  checkOutputDirectory(parent, option);
}

namespace detail {
/// Removes the temporaries `PREFIX<pid>` in `dir` of processes that are gone: a run killed where
/// no handler runs (SIGKILL, the out-of-memory killer) left them, hidden, and no later run took
/// them away (60 and 141 MB of `field build`'s, an environment sweep's). A live process's (or
/// one this process may not signal: another user's) is left; so is anything not so named, and one
/// written in the last minute (a live writer in another PID namespace, whose PID reads as gone
/// here, is writing it now: a reviewer's).
inline void removeDeadTemporaries(const std::filesystem::path& dir, const std::string& prefix) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits[0] == '0' ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;  // (the writer names a PID in decimal, no leading zero)
    std::error_code time_ec;
    const auto written = fs::last_write_time(it->path(), time_ec);
    if (time_ec || fs::file_time_type::clock::now() - written < std::chrono::minutes(1)) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    fs::remove(it->path(), ignored);  // a link: the link, not its target
  }
}
}  // namespace detail

/// Calls `write(stream)` on a temporary file beside `path` (`.NAME.tmp-PID`), then renames it to
/// `path`. Throws InputError (one line naming the path and the system's reason: no permission, disk
/// full, not a directory) if the file cannot be written; the temporary is removed on any failure,
/// including an exception thrown by `write`, and by removeTemporariesNow() on a signal.
///
/// A name that is a symbolic link is written through it (the link stays, its target is replaced
/// atomically); a name that is a device, FIFO or socket (`/dev/null`, `/dev/stdout`) is written
/// into directly and never removed: renaming over it replaced /dev/null with a regular file.
inline void writeFileAtomically(const std::filesystem::path& given,
                                const std::function<void(std::ostream&)>& write,
                                std::ios::openmode mode = std::ios::out) {
  namespace fs = std::filesystem;
  std::error_code status_ec;
  fs::path path = given;  // through its links, also to a target not there yet
  for (int hops = 0; fs::is_symlink(path, status_ec); ++hops) {
    if (hops == 40) throw InputError(given.string() + ": too many levels of symbolic links");
    const fs::path target = fs::read_symlink(path, status_ec);
    if (status_ec)
      throw InputError(given.string() + ": cannot read the link: " + status_ec.message());
    path = target.is_absolute() ? target : path.parent_path() / target;
  }
  const fs::file_status status = fs::status(path, status_ec);
  // An input of this run by any name (a scene's nominal path as --out's path.cl, `view --out`
  // naming the part's mesh): replaced, it was lost without a word.
  if (fs::is_regular_file(status))
    if (const fs::path input = inputAt(path); !input.empty())
      throw InputError(given.string() + ": is an input of this run (" + input.string() +
                       "): writing the output there would replace it; choose another output");
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status)) {
    errno = 0;
    std::ofstream out(path, mode);
    if (!out)
      throw InputError(given.string() +
                       ": cannot open for writing: " + detail::systemReason(errno));
    write(out);
    out.flush();
    if (!out) throw InputError(given.string() + ": cannot write: " + detail::systemReason(errno));
    return;
  }
  if (path.has_parent_path()) createOutputDirectory(path.parent_path());
  // `.NAME.tmp-PID`; a name too long to take the 13 or so characters more (names run to 255
  // bytes) keeps its first 180 and a hash of the whole (a legal 250-byte name was refused).
  std::string stem = path.filename().string();
  if (stem.size() > 180) {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (unsigned char c : stem) h = (h ^ c) * 1099511628211ull;
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    stem = stem.substr(0, 180) + "-" + hex;
  }
  const fs::path tmp = path.parent_path() /
                       ("." + stem + ".tmp-" + std::to_string(static_cast<long>(::getpid())));
  detail::removeDeadTemporaries(path.parent_path(), "." + stem + ".tmp-");
  const detail::TemporaryListing listing{detail::listTemporary(tmp.string())};
  try {
    {
      // The name is this process's (its PID): whatever holds it was left by a dead process or
      // planted, a link to another file that an open would write through (a helper's, in a
      // shared folder). Unlinked (a link, not its target), then created new by this process
      // (O_EXCL | O_NOFOLLOW: a link planted again in between is refused, not followed); the
      // stream writes through that descriptor (opened again by name, a file swapped in
      // between, in a world-writable folder without the sticky bit, would have been written).
      errno = 0;
      detail::beginCreating(listing.slot);
      int created = -1;
      for (int attempt = 0; created < 0 && attempt < 3; ++attempt) {
        ::unlink(tmp.c_str());
        created = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (created < 0 && errno != EEXIST) break;
      }
#if !FIELDPATH_HAS_STDIO_FILEBUF  // another standard library (libc++): opened again by name
      std::ofstream file;
      if (created >= 0) {
        ::close(created);
        file.open(tmp, mode | std::ios::trunc);  // (still bracketed against the handler's sweep)
        if (!file) created = -1;
      }
#endif
      detail::endCreating(listing.slot);
      if (created < 0)
        throw InputError(path.string() + ": cannot open for writing: " +
                         detail::systemReason(errno));
#if FIELDPATH_HAS_STDIO_FILEBUF
      __gnu_cxx::stdio_filebuf<char> file(created, mode | std::ios::out);  // closes `created`
      std::ostream out(&file);
#else
      std::ostream& out = file;
#endif
      errno = 0;
      write(out);
      out.flush();
      if (!out)
        throw InputError(path.string() + ": cannot write: " +
                         detail::writeReason(errno, path.parent_path()));
#if FIELDPATH_HAS_STDIO_FILEBUF
      if (!file.close())
#else
      file.close();
      if (file.fail())
#endif
        throw InputError(path.string() + ": cannot write: " +
                         detail::writeReason(errno, path.parent_path()));
    }
    std::error_code ec;
    if (fs::is_directory(path, ec))
      throw InputError(path.string() + ": is a directory, cannot write a file there");
    // A file replaced keeps its permissions (a 0600 file written through a link became 0644).
    if (fs::is_regular_file(status)) fs::permissions(tmp, status.permissions(), ec);
    fs::rename(tmp, path, ec);
    if (ec) throw InputError(path.string() + ": cannot rename into place: " + ec.message());
    const std::lock_guard<std::mutex> lock(detail::written_mutex);
    detail::written_outputs.push_back(path);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

/// Removes the outputs this process has written (writeFileAtomically) so far: a run that fails
/// on its way (a full disk at the third file) leaves no partial set of outputs either. The CLI's
/// main() calls it before exiting 1 or 2.
inline void removeWrittenOutputs() {
  const std::lock_guard<std::mutex> lock(detail::written_mutex);
  for (const auto& file : detail::written_outputs) {
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
  }
  detail::written_outputs.clear();
  for (const auto& file : detail::claimed_outputs) {
    std::error_code ignored;  // regular files only: a FIFO or a link the user put there stays
    if (std::filesystem::symlink_status(file, ignored).type() ==
            std::filesystem::file_type::regular &&
        inputAt(file).empty())  // nor an input the run read under an output's name
      std::filesystem::remove(file, ignored);
  }
  detail::claimed_outputs.clear();
  for (auto& slot : detail::claimed_slots) slot.state.store(0);
  removeCreatedDirectoryNow();
}

/// Holds `dir` (made now if missing) for this run's outputs until the process ends: a second run
/// writing the same folder meanwhile is refused before its work, with nothing of either taken
/// away (two runs at once left one job's path.cl beside the other's report.json and path.apt,
/// both exiting 0; a failed one took the other's new path.cl away: a helper's finding). An
/// advisory lock (flock) on the folder itself: no lock file, released by the kernel when the
/// process ends however it ends. Where the folder cannot be locked (NFS takes no exclusive flock
/// on a directory) a note says runs are not kept apart there.
inline void lockOutputDirectory(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path key = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  for (const fs::path& held : detail::locked_directories)
    if (held == key) return;
  // Made here only by the run that makes it (two runs starting together both saw it missing: the
  // one whose lock then failed removed the other's folder).
  std::vector<fs::path> made;  // outermost first
  const fs::path full = fs::absolute(dir, ec);
  std::vector<fs::path> missing;
  for (fs::path at = full; !at.empty() && !fs::exists(at, ec) && at != at.parent_path();
       at = at.parent_path())
    missing.insert(missing.begin(), at);
  for (const fs::path& at : missing) {
    if (fs::create_directory(at, ec)) made.push_back(at);
    if (ec) throw InputError(dir.string() + ": cannot create the directory: " + ec.message());
  }
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  const int error = fd < 0 ? errno : ::flock(fd, LOCK_EX | LOCK_NB) != 0 ? errno : 0;
  if (error == EWOULDBLOCK) {
    ::close(fd);
    throw InputError(dir.string() +
                     ": another fieldpath run is writing this folder; wait for it to end, or "
                     "choose another folder");
  }
  if (error != 0) {
    if (fd >= 0) ::close(fd);
    std::fprintf(stderr,
                 "note: %s: the folder cannot be locked here (%s): runs writing it at the same "
                 "time are not kept apart\n",
                 dir.c_str(), detail::systemReason(error).c_str());
  } else {
    detail::locked_directories.push_back(key);  // the descriptor stays open: the lock with it
  }
  // Removed again on failure only by the run that made them and held the folder.
  if (error == 0)
    for (const fs::path& at : made)
      detail::listInSlots(detail::created_directories, detail::kCreatedSlots, at.string());
}

/// The files `names` in `dir` are this command's outputs: a run that fails (exit 1 or 2) removes
/// them where an earlier run left them, as it removes its own (removeWrittenOutputs). A folder
/// then never holds an earlier run's path.cl beside a failed run's error: a script that posts
/// out/path.apt after `generate` would have sent the old path to the machine.
/// Files in `inputs` are never claimed: a scene whose nominal path is `--out`'s path.cl keeps it.
inline void claimOutputs(const std::filesystem::path& dir, std::initializer_list<const char*> names,
                         std::initializer_list<std::filesystem::path> inputs = {}) {
  lockOutputDirectory(dir);  // before claiming: a refused second run takes nothing away
  const std::lock_guard<std::mutex> lock(detail::written_mutex);
  for (const char* name : names) {
    bool input = false;
    for (const auto& file : inputs) {
      std::error_code ec;
      input = input || (!file.empty() && std::filesystem::equivalent(dir / name, file, ec));
    }
    if (input) continue;
    detail::claimed_outputs.push_back(dir / name);
    detail::listInSlots(detail::claimed_slots, detail::kClaimedSlots, (dir / name).string());
  }
}

/// Removes, before the work, the earlier run's files of the outputs claimed (regular files, not
/// inputs): a run killed where no handler runs (SIGKILL, the out-of-memory killer) between two
/// of its renames left its new path.cl beside the earlier run's path.apt and report.json, a set
/// that reads complete (a helper's); now the folder holds this run's files or none.
inline void removeEarlierOutputs() { removeClaimedOutputsNow(); }

/// Refuses, before the work, outputs `names` in `dir` that are inputs this run has read (a scene
/// whose nominal path is --out's path.cl: generate wrote over it, and the next run steered its
/// own output).
inline void refuseOutputsOverInputs(const std::filesystem::path& dir,
                                    std::initializer_list<const char*> names,
                                    const std::string& option) {
  for (const char* name : names)
    if (const std::filesystem::path input = inputAt(dir / name); !input.empty())
      throw InputError(option + ": " + (dir / name).string() + " would replace this run's input " +
                       input.string() + "; choose another " + option);
}

/// Every output of the run is written: from here neither a failure nor a late signal takes them
/// away (one in the process's teardown removed the good outputs of a finished run). Commands call
/// it after their last output, before their summary and notes: a summary that cannot be written
/// (a closed pipe: `| grep -q UNSAFE` stopped reading at generate's warning and its SIGPIPE took
/// the path it warned of, and its folder, away; stdout on a full disk) loses the summary only.
inline void commitOutputs() {
  const std::lock_guard<std::mutex> lock(detail::written_mutex);
  for (auto& slot : detail::claimed_slots) slot.state.store(0);
  for (auto& slot : detail::created_directories) slot.state.store(0);
  detail::claimed_outputs.clear();
  detail::written_outputs.clear();
}

/// Removes the files `names` from `dir` where an earlier run left them and this one does not
/// write them (a check that read no surface, a simulate without `--outputs png`): a folder never
/// mixes two runs' outputs (`view --check` showed an earlier path's surface as this one's).
inline void removeStaleOutputs(const std::filesystem::path& dir,
                               std::span<const char* const> names) {
  for (const char* name : names) {
    std::error_code ec;  // regular files only: a FIFO or a link the user put there stays
    if (std::filesystem::symlink_status(dir / name, ec).type() !=
            std::filesystem::file_type::regular ||
        !inputAt(dir / name).empty())  // nor an input (`simulate --part out/surface.stl`)
      continue;
    std::filesystem::remove(dir / name, ec);
    if (ec && ec != std::errc::no_such_file_or_directory)
      throw InputError((dir / name).string() +
                       ": cannot remove the earlier run's file: " + ec.message());
  }
}
inline void removeStaleOutputs(const std::filesystem::path& dir,
                               std::initializer_list<const char*> names) {
  removeStaleOutputs(dir, std::span<const char* const>(names.begin(), names.size()));
}

/// Writes `text` atomically (see writeFileAtomically).
inline void writeTextAtomically(const std::filesystem::path& path, const std::string& text) {
  writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace fieldpath::common
