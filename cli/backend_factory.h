// Choosing the detection backend from `--backend` and `--device`.
#pragma once

#include <memory>
#include <string>
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

/// `snag --version`'s line about the GPU: the CUDA backend's architectures and runtime, or
/// that this snag was built without it. Touches no device (a version query stays instant, and
/// says what was built, not what this machine has).
std::string cuda_build_line();

/// Number of usable CUDA devices (0 without the CUDA backend, a driver or a GPU).
int cuda_devices();

/// When cuda_devices() is 0 on a machine with an NVIDIA driver, why (cuda::cuda_runtime_problem);
/// else empty.
std::string cuda_runtime_problem();

/// What `--backend auto` means here: "cuda" when snag was built with the CUDA backend and
/// `device` can run its kernels (or does not exist, which the CUDA backend then reports), else
/// "cpu". With `note`, why a GPU that is present, or a driver that is installed, was passed
/// over (a GPU older than the build's architectures, a driver older than its runtime, a device
/// held by another process); empty when nothing needs saying.
std::string_view resolve_auto_backend(int device, std::string* note);

/// "auto": resolve_auto_backend's choice. "cpu": the OpenMP backend with `threads` threads (0:
/// OpenMP's default). "cuda": the CUDA backend on `device`; throws DeviceUnavailable when it was
/// not built, no device is present, `device` is not one of them, or it cannot run this build's
/// kernels (cuda::cuda_device_problem says why). Any other name throws
/// snag::UsageError.
std::unique_ptr<detect::Backend> make_backend(std::string_view name, int threads, int device = 0);

}  // namespace snag::cli
