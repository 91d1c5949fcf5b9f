#include "staged_files.h"

#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include "snag/error.h"
#include "snag/report/write.h"

namespace snag::report {

namespace fs = std::filesystem;

namespace {

// The temporaries on disk, for remove_temporaries_on_signal: fixed slots that a signal handler
// can read (lock-free atomics and plain bytes; nothing allocated). A slot is taken before its
// file is created (kCreating, with the creating thread's id) and marked kTracked once the file
// exists; it is released after the file is removed or renamed. The handler waits a moment for
// other threads' slots that are still being taken or created, so that the file it then unlinks
// exists, and copies a path out before unlinking it, checking that the slot was not released
// and taken again meanwhile (its generation). A run holds a handful at once; past the slots, a
// temporary is not tracked and only a signal would leave it behind. What can still escape: a
// temporary whose slot is taken after the handler has looked at it, in the microseconds before
// the process ends.
constexpr int kTrackedSlots = 64;
enum SlotState : int { kFree = 0, kCreating = 1, kTracked = 2 };
struct TrackedTemporary {
  std::atomic<int> state{kFree};
  std::atomic<uint32_t> generation{0};  ///< counts the slot's takings
  std::atomic<pid_t> creator{0};        ///< the thread creating its file (kCreating)
  char path[4096];
};
TrackedTemporary tracked[kTrackedSlots];
// Set by remove_temporaries_on_signal before it looks at the slots: a temporary created after
// its look is removed by its creator, when the process lives long enough for that.
std::atomic<bool> terminating{false};

/// The slot now holding `path`, in state kCreating, or -1 when none is free or the path is too
/// long. mark_created() once the file exists.
int track(const fs::path& path) {
  const std::string& text = path.native();
  if (text.size() >= sizeof(TrackedTemporary::path)) return -1;
  for (int i = 0; i < kTrackedSlots; ++i) {
    int expected = kFree;
    if (tracked[i].state.compare_exchange_strong(expected, kCreating)) {
      tracked[i].generation.fetch_add(1);
      tracked[i].creator.store(::gettid());
      std::memcpy(tracked[i].path, text.c_str(), text.size() + 1);
      return i;
    }
  }
  return -1;
}

void mark_created(int slot) {
  if (slot >= 0) tracked[slot].state.store(kTracked);
}

void untrack(int slot) {
  if (slot >= 0) tracked[slot].state.store(kFree);
}

/// A final name that a directory holds: rename cannot replace it, and a commit that found out
/// at its second or third rename would leave the reports half replaced. (A link is replaced
/// itself, whatever it points to.)
void require_replaceable(const fs::path& final_path) {
  std::error_code ec;
  if (fs::is_directory(fs::symlink_status(final_path, ec)))
    throw WriteError(final_path, "is a directory, which the report cannot replace");
}

}  // namespace

void remove_temporaries_on_signal() noexcept {
  terminating.store(true);
  const pid_t self = ::gettid();
  for (TrackedTemporary& t : tracked) {
    // Another thread taking this slot or creating its file: up to ~20 ms for it to finish.
    for (int wait = 0; wait < 200 && t.state.load() == kCreating && t.creator.load() != self;
         ++wait) {
      const timespec pause{0, 100000};
      ::nanosleep(&pause, nullptr);
    }
    const uint32_t generation = t.generation.load();
    if (t.state.load() == kFree) continue;
    char path[sizeof t.path];
    std::memcpy(path, t.path, sizeof path);
    path[sizeof path - 1] = '\0';
    if (t.generation.load() == generation && t.state.load() != kFree) ::unlink(path);
  }
}

SignalTracked::SignalTracked(const fs::path& temporary_path) : slot_(track(temporary_path)) {}
SignalTracked::~SignalTracked() {
  untrack(slot_);
}
void SignalTracked::created() {
  mark_created(slot_);
}

fs::path temporary_name(const fs::path& dir, const std::string& name) {
  static std::atomic<unsigned> counter{0};
  return dir / ("." + name + ".tmp-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter.fetch_add(1)));
}

void remove_quietly(const fs::path& path) {
  std::error_code ignored;
  fs::remove(path, ignored);
}

void ensure_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw WriteError(dir, "exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw WriteError(dir, "cannot create the output directory: " + ec.message());
}

StagedFile::StagedFile(fs::path temporary_path, fs::path final_path)
    : temporary_path_(std::move(temporary_path)), final_path_(std::move(final_path)) {
  out_.open(temporary_path_, std::ios::binary | std::ios::trunc);
  const int err = errno;
  if (!out_) throw WriteError(final_path_, std::string("cannot create: ") + std::strerror(err));
}

void StagedFile::check() const {
  if (!out_) throw WriteError(final_path_, "write failed (disk full?)");
}

void StagedFile::close() {
  if (!out_.is_open()) return;
  out_.close();
  check();
}

StagedFiles::StagedFiles(fs::path dir) : dir_(std::move(dir)) {
  ensure_directory(dir_);
}

StagedFiles::~StagedFiles() {
  // After a successful commit() no temporary is left to remove; otherwise every one goes,
  // complete or not. The stream is closed before its file is removed.
  for (Entry& e : entries_) {
    e.file.reset();
    remove_quietly(e.temporary_path);
    untrack(e.tracked_slot);
  }
}

StagedFile& StagedFiles::open(fs::path temporary_path, const std::string& name, bool scratch) {
  if (committed_) throw InternalError("report: " + name + " created after the commit");
  entries_.push_back({temporary_path, nullptr, scratch, track(temporary_path)});
  try {
    entries_.back().file = std::make_unique<StagedFile>(std::move(temporary_path), dir_ / name);
    mark_created(entries_.back().tracked_slot);
    if (terminating.load()) remove_quietly(entries_.back().temporary_path);  // see `terminating`
  } catch (...) {
    // Not created, or created and not writable: either way it is not part of the set.
    remove_quietly(entries_.back().temporary_path);
    untrack(entries_.back().tracked_slot);
    entries_.pop_back();
    throw;
  }
  return *entries_.back().file;
}

StagedFile& StagedFiles::create(const std::string& name) {
  require_replaceable(dir_ / name);  // at once, rather than after an hour of checking
  return open(temporary_name(dir_, name), name, false);
}

StagedFile& StagedFiles::create_scratch(const std::string& name, const std::string& part) {
  return open(temporary_name(dir_, name + "." + part), name, true);
}

void StagedFiles::commit() {
  if (committed_) throw InternalError("report: files committed twice");
  committed_ = true;
  for (Entry& e : entries_) e.file->close();
  for (Entry& e : entries_)
    if (e.scratch) {
      remove_quietly(e.temporary_path);
      untrack(std::exchange(e.tracked_slot, -1));
    }
  // Every final name checked again before the first rename (a directory made there since
  // create()). What can still fail between two renames (staged_files.h): the directory going
  // or made read-only, or a directory made at a later name in the microseconds between.
  for (const Entry& e : entries_)
    if (!e.scratch) require_replaceable(e.file->final_path());
  for (Entry& e : entries_) {
    if (e.scratch) continue;
    std::error_code ec;
    fs::rename(e.temporary_path, e.file->final_path(), ec);
    if (ec) throw WriteError(e.file->final_path(), "cannot rename into place: " + ec.message());
    untrack(std::exchange(e.tracked_slot, -1));
  }
}

}  // namespace snag::report
