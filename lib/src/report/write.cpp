#include "snag/report/write.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "snag/report/csv.h"
#include "snag/report/json.h"

namespace snag::report {

namespace fs = std::filesystem;

namespace {

/// A hidden name in the same directory (rename is atomic only within one filesystem), unique
/// per process and call so two runs writing into one directory never share a temporary.
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

}  // namespace

void prepare_output_dir(const fs::path& dir) {
  ensure_directory(dir);
  const fs::path probe = temporary_name(dir, "probe");
  std::ofstream out(probe, std::ios::binary);
  const int err = errno;
  if (!out)
    throw WriteError(dir,
                     std::string("cannot write into the output directory: ") + std::strerror(err));
  out.close();
  remove_quietly(probe);
}

void write_files_atomically(const fs::path& dir, const std::vector<OutputFile>& files) {
  ensure_directory(dir);
  std::vector<fs::path> temporaries;
  try {
    for (const OutputFile& file : files) {
      const fs::path tmp = temporary_name(dir, file.name);
      temporaries.push_back(tmp);
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out)
        throw WriteError(dir / file.name, std::string("cannot create: ") + std::strerror(errno));
      file.write(out);
      out.close();
      // close() flushes; a full disk shows up here, not at the first write.
      if (!out) throw WriteError(dir / file.name, "write failed (disk full?)");
    }
    for (size_t i = 0; i < files.size(); ++i) {
      std::error_code ec;
      fs::rename(temporaries[i], dir / files[i].name, ec);
      if (ec) throw WriteError(dir / files[i].name, "cannot rename into place: " + ec.message());
    }
  } catch (...) {
    for (const fs::path& tmp : temporaries) remove_quietly(tmp);
    throw;
  }
}

void write_reports(const fs::path& dir, const Report& report) {
  write_files_atomically(dir,
                         {{"pairs.csv", [&](std::ostream& out) { write_pairs_csv(out, report); }},
                          {"frames.csv", [&](std::ostream& out) { write_frames_csv(out, report); }},
                          {"report.json", [&](std::ostream& out) { out << report_json(report); }}});
}

}  // namespace snag::report
