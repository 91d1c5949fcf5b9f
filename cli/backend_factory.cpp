#include "backend_factory.h"

#include <string>

#include "snag/detect/cpu_backend.h"
#include "snag/error.h"

namespace snag::cli {

std::unique_ptr<detect::Backend> make_backend(std::string_view name, int threads) {
  if (name == "auto" || name == "cpu") return detect::make_cpu_backend(threads);
  if (name == "cuda")
    throw UsageError(
        "--backend cuda: the CUDA backend is not built in this version of snag; use "
        "--backend cpu (or auto)");
  throw UsageError("--backend: unknown backend '" + std::string(name) +
                   "' (expected auto, cpu or cuda)");
}

}  // namespace snag::cli
