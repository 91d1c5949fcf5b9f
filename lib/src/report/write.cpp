#include "snag/report/write.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <numeric>

#include "snag/report/stream.h"
#include "staged_files.h"

namespace snag::report {

namespace fs = std::filesystem;

void prepare_output_dir(const fs::path& dir) {
  ensure_directory(dir);
  const fs::path probe = temporary_name(dir, "probe");
  SignalTracked tracked(probe);  // a signal meanwhile removes it too
  std::ofstream out(probe, std::ios::binary);
  const int err = errno;
  if (!out) {
    remove_quietly(probe);
    throw WriteError(dir,
                     std::string("cannot write into the output directory: ") + std::strerror(err));
  }
  tracked.created();
  out.close();
  remove_quietly(probe);
}

OutputDirectory::OutputDirectory(const fs::path& dir) {
  const bool climbs =
      std::any_of(dir.begin(), dir.end(), [](const fs::path& part) { return part == ".."; });
  std::error_code ec;
  fs::path path = fs::absolute(dir, ec);
  if (!ec && path.filename().empty()) path = path.parent_path();  // "out/"
  for (; !climbs && !ec && path.has_relative_path() && !fs::exists(path, ec);
       path = path.parent_path())
    created_.push_back(path);
  try {
    prepare_output_dir(dir);
  } catch (...) {
    remove_created();
    throw;
  }
}

OutputDirectory::~OutputDirectory() {
  remove_created();
}

void OutputDirectory::remove_created() noexcept {
  std::error_code ignored;  // a directory no longer empty (another run's reports) stays
  for (const fs::path& path : created_) fs::remove(path, ignored);
}

void write_files_atomically(const fs::path& dir, const std::vector<OutputFile>& files) {
  StagedFiles staged(dir);
  for (const OutputFile& file : files) {
    StagedFile& staged_file = staged.create(file.name);
    file.write(staged_file.out());
    staged_file.close();
  }
  staged.commit();
}

void write_reports(const fs::path& dir, const Report& report) {
  // The stream takes frames in frame order; Report::frames is documented in that order, and a
  // report recorded otherwise is written sorted (stably), as write_pairs_csv sorts its rows.
  std::vector<size_t> order(report.frames.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
    return report.frames[x].frame < report.frames[y].frame;
  });
  ReportStream stream(dir, report.snag_version, report.settings, report.inputs.objects);
  for (size_t i : order) stream.add(report.frames[i]);
  stream.finish(report.inputs, report.builds, report.rebuilds, report.wall_seconds);
}

}  // namespace snag::report
