// Choosing the detection backend from `--backend` and `--device`.
#pragma once

#include <memory>
#include <string_view>

#include "snag/detect/backend.h"
#include "snag/error.h"

namespace snag::cli {

/// The names `--backend` accepts.
inline constexpr std::string_view backend_names[] = {"auto", "cpu", "cuda"};

/// `--backend cuda` cannot be honoured: this snag was built without the CUDA backend, or no
/// usable CUDA device is here (exit status 4, like other device failures).
class DeviceUnavailable : public InternalError {
 public:
  using InternalError::InternalError;
};

/// Whether this snag was built with the CUDA backend.
bool cuda_built();

/// Number of usable CUDA devices (0 without the CUDA backend, a driver or a GPU).
int cuda_devices();

/// "auto": the CUDA backend on `device` when snag was built with it and a CUDA device is
/// present, else the CPU. "cpu": the OpenMP backend with `threads` threads (0: OpenMP's
/// default). "cuda": the CUDA backend on `device`; throws DeviceUnavailable when it was not
/// built, no device is present, or `device` is not one of them. Any other name throws
/// snag::UsageError.
std::unique_ptr<detect::Backend> make_backend(std::string_view name, int threads, int device = 0);

}  // namespace snag::cli
