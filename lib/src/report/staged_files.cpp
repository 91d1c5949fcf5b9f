#include "staged_files.h"

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
// can read (lock-free atomics and plain bytes; nothing allocated). A slot is tracked before its
// file is created and released after the file is removed or renamed, so a signal at any point
// finds every temporary that exists (and perhaps one that does not yet or no longer: its
// unlink fails harmlessly). A run holds a handful at once; past the slots, a temporary is not
// tracked and only a signal would leave it behind.
constexpr int kTrackedSlots = 64;
enum SlotState : int { kFree = 0, kFilling = 1, kTracked = 2 };
struct TrackedTemporary {
  std::atomic<int> state{kFree};
  char path[4096];
};
TrackedTemporary tracked[kTrackedSlots];
// Set by remove_temporaries_on_signal before it looks at the slots. Another thread may be
// creating a temporary meanwhile: if the handler's look missed its slot, or unlinked the path
// before the file existed, the creator sees this set once its file exists (all seq_cst: the
// handler's store precedes its loads, the creator's slot store precedes its load of this)
// and removes the file itself.
std::atomic<bool> terminating{false};

/// The slot now holding `path`, or -1 when none is free or the path is too long.
int track(const fs::path& path) {
  const std::string& text = path.native();
  if (text.size() >= sizeof(TrackedTemporary::path)) return -1;
  for (int i = 0; i < kTrackedSlots; ++i) {
    int expected = kFree;
    if (tracked[i].state.compare_exchange_strong(expected, kFilling)) {
      std::memcpy(tracked[i].path, text.c_str(), text.size() + 1);
      tracked[i].state.store(kTracked);
      return i;
    }
  }
  return -1;
}

void untrack(int slot) {
  if (slot >= 0) tracked[slot].state.store(kFree, std::memory_order_release);
}

}  // namespace

void remove_temporaries_on_signal() noexcept {
  terminating.store(true);
  for (TrackedTemporary& t : tracked)
    if (t.state.load() == kTracked) ::unlink(t.path);
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
  for (Entry& e : entries_) {
    if (e.scratch) continue;
    std::error_code ec;
    fs::rename(e.temporary_path, e.file->final_path(), ec);
    if (ec) throw WriteError(e.file->final_path(), "cannot rename into place: " + ec.message());
    untrack(std::exchange(e.tracked_slot, -1));
  }
}

}  // namespace snag::report
