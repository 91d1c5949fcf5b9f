// Typed errors thrown by the library; cli/main.cpp turns them into exit statuses.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace snag {

/// Bad input: a file that cannot be read or that breaks its format's rules (exit status 3).
/// The message names the file, the line (text formats) or byte offset (binary formats), what
/// was found and what was expected.
class InputError : public std::runtime_error {
 public:
  InputError(std::string path, int64_t line, std::string what, int64_t byte_offset = -1)
      : std::runtime_error(format(path, line, byte_offset, what)),
        path_(std::move(path)),
        line_(line),
        byte_offset_(byte_offset) {}
  const std::string& path() const { return path_; }
  int64_t line() const { return line_; }                ///< 1-based, 0 when not a line
  int64_t byte_offset() const { return byte_offset_; }  ///< -1 when not a byte offset

 private:
  // Appends rather than chaining operator+: GCC 12 warns falsely (-Wrestrict) on the chain.
  static std::string format(const std::string& path, int64_t line, int64_t offset,
                            const std::string& what) {
    std::string message = path;
    if (line > 0) message.append(":").append(std::to_string(line));
    if (offset >= 0) message.append(" (byte ").append(std::to_string(offset)).append(")");
    message.append(": ").append(what);
    return message;
  }
  std::string path_;
  int64_t line_;
  int64_t byte_offset_;
};

/// A command line that cannot be honoured (exit status 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A broken invariant or a failing device call (exit status 4).
class InternalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Memory for a frame's buffers ran out where snag cannot choose less: on the GPU (a frame with
/// millions of candidate pairs, a small GPU or one shared with another job), or the host memory
/// locked for transfers to it. Exit status 4, as a failing device call, but no fault of snag's;
/// the message says what did not fit and, for the GPU, how much was free; what to do about it is
/// the caller's to say.
class OutOfMemory : public InternalError {
 public:
  using InternalError::InternalError;
};

}  // namespace snag
