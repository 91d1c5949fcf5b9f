#include "staged_files.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "snag/error.h"
#include "snag/report/write.h"

namespace snag::report {

namespace fs = std::filesystem;

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
  }
}

StagedFile& StagedFiles::open(fs::path temporary_path, const std::string& name, bool scratch) {
  if (committed_) throw InternalError("report: " + name + " created after the commit");
  entries_.push_back({temporary_path, nullptr, scratch});
  try {
    entries_.back().file = std::make_unique<StagedFile>(std::move(temporary_path), dir_ / name);
  } catch (...) {
    // Not created, or created and not writable: either way it is not part of the set.
    remove_quietly(entries_.back().temporary_path);
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
    if (e.scratch) remove_quietly(e.temporary_path);
  for (Entry& e : entries_) {
    if (e.scratch) continue;
    std::error_code ec;
    fs::rename(e.temporary_path, e.file->final_path(), ec);
    if (ec) throw WriteError(e.file->final_path(), "cannot rename into place: " + ec.message());
  }
}

}  // namespace snag::report
