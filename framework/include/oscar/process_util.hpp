#pragma once
/// @file What every OSCAR program does the same way: find the programs installed beside it, turn
/// SIGINT/SIGTERM into an orderly stop, and keep the heap suited to large cues.

#include <signal.h>
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace oscar {

/// The directory of the running program (where oscar-run, oscar-monitor, ... are installed).
std::filesystem::path program_dir();
/// `<program_dir>/<program>`.
std::string sibling_program(const std::string& program);
/// Where `program` is found on $PATH (as execvp would look: the first executable file), if it is.
std::optional<std::filesystem::path> find_on_path(const std::string& program);

/// Blocks SIGINT and SIGTERM in this thread and every thread started after it, so they can be
/// waited for with wait_for_stop(). Call first thing in main().
sigset_t block_stop_signals();
/// True if SIGINT or SIGTERM arrived within `timeout`.
bool wait_for_stop(const sigset_t& signals, std::chrono::milliseconds timeout);

/// True if process `pid` has a thread that is neither a zombie nor dead. A killed multi-threaded
/// process shows its main thread as a zombie while its other threads still exit and hold its
/// files (and with them the locks of its shared memory): it lives until the last one is gone.
/// A zombie whose parent has not reaped it yet is dead (kill(pid, 0) would still find it).
bool process_lives(pid_t pid);

/// The inodes of the files mapped into this process under `path` (/proc/self/maps), one per
/// mapping; a file removed since is among them (the kernel keeps it while mapped).
std::vector<ino_t> inodes_mapped_from(const std::string& path);

/// Keeps freed cue memory (camera images of hundreds of KB) inside the process instead of handing
/// it back to the kernel after each cue: large blocks come from the heap, not from a fresh mmap,
/// and the heap is trimmed only when more than 64 MB lie free at its top. glibc's defaults
/// otherwise cost a page fault per 4 KB of every received image (442 KB: +40 µs per cue, see
/// docs/benchmarks.md). Call once at start-up in processes that carry cues.
void keep_cue_memory_in_process();

/// Touches `bytes` of heap now and keeps them for later allocations (the real-time recipe of
/// "pre-faulting the heap"): the first write to fresh memory costs a page fault per 4 KB, about
/// 1 ms for a 442 KB image on the 2-core virtual machine of docs/benchmarks.md. Call from the
/// main thread before the time-critical part: blocks it allocates later, and those of threads
/// reallocating them, come from this memory. Implies keep_cue_memory_in_process().
void prefault_heap(std::size_t bytes);

/// Asks the kernel to wake the calling thread when its sleep ends, not up to 50 us later: timer
/// slack 1 ns instead of Linux's default 50 us, which lets the kernel batch wake-ups (real-time
/// threads have none). For threads that publish on a schedule, e.g. oscar replay's lanes.
void wake_on_time();

}  // namespace oscar
