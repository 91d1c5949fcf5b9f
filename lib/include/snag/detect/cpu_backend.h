// The CPU backend: the paper's tree and traversal with OpenMP, one task per leaf.
#pragma once

#include <memory>

#include "snag/detect/backend.h"

namespace snag::detect {

/// `threads` <= 0 uses OpenMP's default (all cores).
std::unique_ptr<Backend> make_cpu_backend(int threads = 0);

}  // namespace snag::detect
