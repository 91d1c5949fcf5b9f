// Frame files: one read into memory, then the reader picked by the extension.
#include "snag/io/read_mesh.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include "file_buffer.h"
#include "snag/error.h"
#include "snag/io/assimp_reader.h"
#include "snag/io/obj_reader.h"
#include "snag/io/ply_reader.h"
#include "structure_cache.h"

namespace snag::io {
std::string lowercase_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return ext;
}

namespace {

class OpenFile {
 public:
  explicit OpenFile(const std::filesystem::path& path) : path_(path) {
    do {
      fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    } while (fd_ < 0 && errno == EINTR);
    if (fd_ < 0) fail("cannot open");
    struct stat st {};
    if (::fstat(fd_, &st) != 0) fail("cannot stat");
    if (S_ISDIR(st.st_mode))
      throw InputError(path_.string(), 0, "is a directory; expected a mesh file");
    // A device has no end to read to (/dev/zero, /dev/urandom) or is a terminal: found by
    // fuzzing, /dev/zero named as a frame was read until memory ran out. Pipes are read whole.
    if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode))
      throw InputError(path_.string(), 0, "is a device; expected a mesh file");
    size_ = S_ISREG(st.st_mode) ? static_cast<int64_t>(st.st_size) : -1;
  }
  ~OpenFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;

  /// The size of a regular file when it was opened; -1 for a pipe.
  int64_t size() const { return size_; }

  /// Reads up to `n` bytes into `dst`, fewer only at the end of the file (a file that shrank).
  size_t read_up_to(char* dst, size_t n) {
    size_t done = 0;
    while (done < n) {
      const ssize_t got = ::read(fd_, dst + done, n - done);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) fail("cannot read");
      if (got == 0) break;
      done += static_cast<size_t>(got);
    }
    return done;
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw InputError(path_.string(), 0, std::string(what) + ": " + std::strerror(errno));
  }
  const std::filesystem::path& path_;
  int fd_ = -1;
  int64_t size_ = -1;
};

/// Reads a pipe to its end.
std::string read_stream(OpenFile& file) {
  std::string bytes;
  size_t used = 0;
  for (;;) {
    bytes.resize(used + (1 << 16));
    const size_t got = file.read_up_to(bytes.data() + used, 1 << 16);
    used += got;
    if (got < (1 << 16)) break;
  }
  bytes.resize(used);
  return bytes;
}

}  // namespace

std::string read_file_bytes(const std::filesystem::path& path) {
  OpenFile file(path);
  if (file.size() < 0) return read_stream(file);
  std::string bytes(static_cast<size_t>(file.size()), '\0');
  // A file still being written is read up to the size it had: the parser reports where it is cut.
  bytes.resize(file.read_up_to(bytes.data(), bytes.size()));
  return bytes;
}

namespace detail {

std::string_view read_into_thread_buffer(const std::filesystem::path& path) {
  struct Buffer {
    std::unique_ptr<char[]> data;  // uninitialized: read() fills it
    size_t capacity = 0;
  };
  thread_local Buffer buffer;
  OpenFile file(path);
  if (file.size() < 0) {
    const std::string bytes = read_stream(file);
    if (bytes.size() > buffer.capacity) {
      buffer.data.reset(new char[bytes.size()]);
      buffer.capacity = bytes.size();
    }
    std::memcpy(buffer.data.get(), bytes.data(), bytes.size());
    return {buffer.data.get(), bytes.size()};
  }
  const auto size = static_cast<size_t>(file.size());
  if (size > buffer.capacity) {
    buffer.data.reset();  // release first: the peak is one buffer, not two
    buffer.data.reset(new char[size]);
    buffer.capacity = size;
  }
  return {buffer.data.get(), file.read_up_to(buffer.data.get(), size)};
}

}  // namespace detail

FrameReader::FrameReader() : cache_(std::make_unique<detail::StructureCache>()) {}
FrameReader::~FrameReader() = default;
FrameReader::FrameReader(FrameReader&&) noexcept = default;
FrameReader& FrameReader::operator=(FrameReader&&) noexcept = default;

mesh::Mesh FrameReader::read(const std::filesystem::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".obj")
    return detail::read_obj_reusing(detail::read_into_thread_buffer(path), path.string(), *cache_);
  if (ext == ".ply")
    return detail::read_ply_reusing(detail::read_into_thread_buffer(path), path.string(), *cache_);
  return read_mesh(path);
}

int64_t FrameReader::frames_reused() const {
  return cache_->reused;
}

mesh::Mesh read_mesh(const std::filesystem::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".obj") return read_obj_file(path);
  if (ext == ".ply") return read_ply_file(path);
  return read_with_assimp(path);
}

}  // namespace snag::io
