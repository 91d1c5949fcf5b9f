// Reading a frame file into a per-thread buffer that is reused from frame to frame. Private to
// lib/src/io.
#pragma once

#include <filesystem>
#include <string_view>

namespace snag::io::detail {

/// The whole file, read with one read() into a buffer owned by the calling thread. The view is
/// valid until the same thread calls this again. A sequence reads frames of about one size, so
/// after the first frame no page is allocated or faulted in: on a 1.2 MB OBJ that is a third of
/// the time to read and parse it. The buffer keeps the largest file's size per thread.
/// Throws snag::InputError when the file cannot be opened or read.
std::string_view read_into_thread_buffer(const std::filesystem::path& path);

}  // namespace snag::io::detail
