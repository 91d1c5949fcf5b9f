# Every dependency is a Debian package (see the Makefile's install step).
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(CGAL REQUIRED)
find_package(assimp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(FastFloat REQUIRED)
find_package(Threads REQUIRED)
# Benchmark only (`snag bench io` reads the same frames with it); optional.
find_package(tinyobjloader QUIET)
if(SNAG_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()

# Strict IEEE evaluation: the orientation filters' error bounds assume every product and sum is
# rounded on its own, so no contraction into fused multiply-adds, on the host or the device.
set(SNAG_STRICT_FP_FLAGS -ffp-contract=off -fno-fast-math)
