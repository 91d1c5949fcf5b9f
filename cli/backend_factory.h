// Choosing the detection backend from `--backend`.
#pragma once

#include <memory>
#include <string_view>

#include "snag/detect/backend.h"

namespace snag::cli {

/// The names `--backend` accepts. "cuda" is accepted so that asking for it gets a clear
/// answer from make_backend rather than a generic "not in the list" from the parser.
inline constexpr std::string_view backend_names[] = {"auto", "cpu", "cuda"};

/// "auto": the best backend built into this snag and usable here (today: cpu). "cpu": the
/// OpenMP backend with `threads` threads (0: OpenMP's default). "cuda": throws
/// snag::UsageError, since this version of snag has no CUDA backend. Any other name throws
/// snag::UsageError.
std::unique_ptr<detect::Backend> make_backend(std::string_view name, int threads);

}  // namespace snag::cli
