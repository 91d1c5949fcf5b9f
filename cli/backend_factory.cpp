#include "backend_factory.h"

#include <string>

#include "snag/detect/cpu_backend.h"
#include "snag/error.h"

#ifdef SNAG_HAVE_CUDA
#include "snag/cuda/cuda_backend.h"
#endif

namespace snag::cli {

bool cuda_built() {
#ifdef SNAG_HAVE_CUDA
  return true;
#else
  return false;
#endif
}

std::string cuda_build_line() {
#ifdef SNAG_HAVE_CUDA
  return "CUDA backend: " + cuda::cuda_build_description();
#else
  return std::string("CUDA backend: not built (") + SNAG_WITHOUT_CUDA_BECAUSE + ")";
#endif
}

int cuda_devices() {
#ifdef SNAG_HAVE_CUDA
  return cuda::cuda_device_count();
#else
  return 0;
#endif
}

std::string cuda_runtime_problem() {
#ifdef SNAG_HAVE_CUDA
  return cuda::cuda_runtime_problem();
#else
  return {};
#endif
}

namespace {

std::unique_ptr<detect::Backend> make_cuda(int device) {
#ifdef SNAG_HAVE_CUDA
  const int count = cuda::cuda_device_count();
  if (count == 0) {
    const std::string problem = cuda::cuda_runtime_problem();
    throw DeviceUnavailable(
        "--backend cuda: no CUDA device is usable here (" +
        (problem.empty() ? std::string("no NVIDIA GPU, or no driver for it") : problem) +
        "); use --backend cpu (or auto)");
  }
  if (device < 0 || device >= count)
    throw DeviceUnavailable("--device " + std::to_string(device) + ": this machine has " +
                            std::to_string(count) + " CUDA device" + (count == 1 ? "" : "s") +
                            ", numbered from 0");
  if (const std::string problem = cuda::cuda_device_problem(device); !problem.empty())
    throw DeviceUnavailable("--backend cuda: " + problem + "; use --backend cpu (or auto)");
  return cuda::make_cuda_backend(device);
#else
  (void)device;
  throw DeviceUnavailable(std::string("--backend cuda: this snag was built without the CUDA "
                                      "backend (") +
                          SNAG_WITHOUT_CUDA_BECAUSE +
                          "); use --backend cpu (or auto), or rebuild with the CUDA toolkit");
#endif
}

}  // namespace

std::string_view resolve_auto_backend(int device, std::string* note) {
  if (note) note->clear();
#ifdef SNAG_HAVE_CUDA
  const int count = cuda::cuda_device_count();
  if (count == 0) {
    if (note) {
      const std::string problem = cuda::cuda_runtime_problem();
      if (!problem.empty()) *note = "checking on the CPU: " + problem;
    }
    return "cpu";
  }
  // A --device that does not exist is the user's error, which the CUDA backend reports.
  if (device < 0 || device >= count) return "cuda";
  const std::string problem = cuda::cuda_device_problem(device);
  if (problem.empty()) return "cuda";
  if (note) *note = "checking on the CPU: " + problem;
  return "cpu";
#else
  (void)device;
  return "cpu";
#endif
}

std::unique_ptr<detect::Backend> make_backend(std::string_view name, int threads, int device) {
  if (name == "auto") name = resolve_auto_backend(device, nullptr);
  if (name == "cpu") return detect::make_cpu_backend(threads);
  if (name == "cuda") return make_cuda(device);
  throw UsageError("--backend: unknown backend '" + std::string(name) +
                   "' (expected auto, cpu or cuda)");
}

}  // namespace snag::cli
