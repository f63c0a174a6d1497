#pragma once
/// What a signal does to a run's outputs: SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE remove the
/// temporaries being written, the outputs the run claimed and the folders it made (atomic_file.h
/// keeps them where a handler can read them), end a helper writing outputs, say so in one line
/// and end the process by the signal; SIGBUS at a mapped input (input_file.h) is one line and
/// exit 1. Split out of atomic_file.h: the handlers, not the writing.
#include <poll.h>
#include <signal.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/input_file.h"

namespace fieldpath::common {

namespace detail {
/// A helper process writing outputs of this run (study's python3 plotter), or 0: a signal ends it
/// first, so that it renames nothing into place after the run is gone (SIGTERM to the program
/// alone left the plotter to move a PNG into --out a second after the exit: a study sweep's).
inline std::atomic<pid_t> output_helper{0};

inline void writeAll(int fd, const char* text) noexcept {
  for (std::size_t n = std::strlen(text); n > 0;) {
    const ssize_t w = ::write(fd, text, n);
    if (w <= 0) return;
    text += w, n -= static_cast<std::size_t>(w);
  }
}

/// The line an interrupted run ends with (a run killed by `timeout` or Ctrl-C said nothing, its
/// log read as if it had stopped on its own): the signal, and whether the outputs it was to write
/// were taken away (`claimed`). Not for SIGPIPE (`| head` done reading: nothing to tell). Said
/// after the files are removed, and only where it cannot block: SIGPIPE and SIGTTOU ignored (a
/// closed stderr ended the run by SIGPIPE, not by its signal), and not said where stderr takes no
/// bytes now (poll: a full pipe, `2>&1 | less` not read, or a terminal paused by Ctrl-S held the
/// run in the handler, its signal blocked there). Async-signal-safe: one write of a line built on
/// the stack.
inline void sayInterrupted(int signal_number, bool claimed) noexcept {
  const char* name = signal_number == SIGINT    ? "SIGINT"
                     : signal_number == SIGTERM ? "SIGTERM"
                     : signal_number == SIGHUP  ? "SIGHUP"
                     : signal_number == SIGQUIT ? "SIGQUIT"
                                                : nullptr;
  if (!name) return;
  char line[160] = "";
  // On a terminal the progress line may be open (drawn with "\r", no line end): ended first.
  struct termios terminal {};
  if (::tcgetattr(STDERR_FILENO, &terminal) == 0) std::strcat(line, "\n");
  std::strcat(line, "fieldpath: interrupted by ");
  std::strcat(line, name);
  std::strcat(line, claimed ? ": its outputs not written, nor an earlier run's left under their "
                              "names\n"
                            : "\n");
  // SIGTTOU ignored too: a background run on a terminal set to `stty tostop` was stopped by the
  // line's write, not ended by its signal (a review's); ignored, the write is let through.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  ::sigaction(SIGPIPE, &ignore, nullptr);
  ::sigaction(SIGTTOU, &ignore, nullptr);
  // A pipe with room takes a line under PIPE_BUF whole; a stopped terminal reports no room.
  struct pollfd err {
    STDERR_FILENO, POLLOUT, 0
  };
  if (::poll(&err, 1, 0) == 1 && (err.revents & POLLOUT) != 0) writeAll(STDERR_FILENO, line);
}

extern "C" inline void removeTemporariesAndDie(int signal_number) {
  if (const pid_t helper = output_helper.load(); helper > 0) ::kill(helper, SIGKILL);
  bool claimed = false;
  for (auto& slot : claimed_slots) claimed = claimed || slot.state.load() == 2;
  removeTemporariesNow();
  removeClaimedOutputsNow();
  removeCreatedDirectoryNow();
  sayInterrupted(signal_number, claimed);
  ::raise(signal_number);  // SA_RESETHAND restored the default action: die of the signal
}
}  // namespace detail

namespace detail {
/// SIGBUS at an address of a mapped input (listMappedInput: the file was cut short while it was
/// read, and it crashed with "Bus error", an empty output folder left): one line naming it, the
/// run's files removed as for a failed run, exit 1; the first thread in says it (the readers
/// run in parallel). Any other SIGBUS (a fault elsewhere, `kill -BUS`) keeps its default action:
/// the handler steps aside and the fault, or the signal, recurs. Async-signal-safe.
inline std::atomic<int> bus_reported{0};
extern "C" inline void inputCutShortAndExit(int signal_number, siginfo_t* info, void*) {
  const char* name = info && info->si_code > 0 ? mappedInputAt(info->si_addr) : nullptr;
  if (!name) {
    ::signal(signal_number, SIG_DFL);
    if (!info || info->si_code <= 0) ::raise(signal_number);  // sent, not a fault: re-sent
    return;
  }
  if (bus_reported.exchange(1) != 0)
    while (true) ::pause();  // another thread is saying it and ending the process
  writeAll(STDERR_FILENO, "fieldpath: error: ");
  writeAll(STDERR_FILENO, name);
  writeAll(STDERR_FILENO,
           ": cut short while it was read (another program wrote it): run again on the file as it "
           "is\n");
  removeTemporariesNow();
  removeClaimedOutputsNow();
  removeCreatedDirectoryNow();
  ::_exit(1);
}
}  // namespace detail

/// SIGINT, SIGTERM, SIGHUP (the terminal closed), SIGQUIT and SIGPIPE (`| head` done reading)
/// remove the temporaries being written (no partial file under any name) and the outputs the run
/// claimed (no earlier run's file beside an interrupted one), then end the process by the signal
/// as usual. SIGXFSZ (`ulimit -f`) is ignored: the write fails, the run reports it as any
/// failed write and removes its files (killed by it, its temporaries stayed). SIGBUS (a mapped
/// input cut short) is one line and exit 1, the files removed as for a failed run. The CLI's
/// main() installs it first thing.
inline void installTemporaryCleanupOnSignals() {
  struct sigaction action {};
  action.sa_handler = detail::removeTemporariesAndDie;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) {
    // A signal the run was started ignoring stays ignored (`nohup`, a shell's background job:
    // a HUP then killed the run and took its outputs).
    struct sigaction before {};
    if (sigaction(signal_number, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    sigaction(signal_number, &action, nullptr);
  }
  ::signal(SIGXFSZ, SIG_IGN);
  struct sigaction bus {};
  bus.sa_sigaction = detail::inputCutShortAndExit;
  bus.sa_flags = SA_SIGINFO;
  sigemptyset(&bus.sa_mask);
  sigaction(SIGBUS, &bus, nullptr);
}

}  // namespace fieldpath::common
