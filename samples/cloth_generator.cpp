// snag-cloth: simulates a square cloth dropped over a sphere, with no self-collision response,
// and writes one OBJ file per frame. See samples/README.md for the model and the options.
#include "cloth_grid.h"
#include "cloth_sim.h"
#include "obj_writer.h"
#include "sphere_mesh.h"

#include <omp.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using snag::samples::GridSize;

// "N" (N x N quads) or "NxM" (N along x, M along z).
GridSize parse_grid(const std::string& text) {
  const auto fail = [&] {
    return std::invalid_argument("--grid expects N or NxM with N, M >= 1, got '" + text + "'");
  };
  std::size_t used = 0;
  GridSize grid;
  try {
    grid.nx = std::stoi(text, &used);
    if (used == text.size()) {
      grid.ny = grid.nx;
    } else if (text[used] == 'x' || text[used] == 'X') {
      const std::string rest = text.substr(used + 1);
      grid.ny = std::stoi(rest, &used);
      if (used != rest.size()) throw fail();
    } else {
      throw fail();
    }
  } catch (const std::logic_error&) {
    throw fail();
  }
  if (grid.nx < 1 || grid.ny < 1) throw fail();
  return grid;
}

// "prefix.%04d.obj", wider when the number needs it.
std::string frame_name(const std::string& prefix, int frame) {
  char number[16];
  std::snprintf(number, sizeof number, "%04d", frame);
  return prefix + "." + number + ".obj";
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "snag-cloth: drops a mass-spring cloth over a sphere, without self-collision, so "
      "that it folds through itself; writes one OBJ file per frame."};
  app.get_formatter()->column_width(34);

  std::string grid_text;
  std::int64_t triangles = 0;
  int frames = 60;
  double fps = 30.0;
  int substeps = 0;
  int first_frame = 1;
  std::string output_dir = ".";
  std::string prefix = "cloth";
  int decimals = 6;
  std::uint64_t seed = 1;
  std::string sphere_path;
  int sphere_segments = 32;
  double write_sphere_radius = std::nan("");
  int threads = 0;
  bool quiet = false;
  snag::samples::SceneParams scene;
  snag::samples::MaterialParams material;
  double ground_height = std::nan("");

  auto* grid_option =
      app.add_option("--grid", grid_text, "Quads per side: N (N x N) or NxM")->type_name("N|NxM");
  auto* triangles_option =
      app.add_option("--triangles", triangles,
                     "Pick the near-square grid closest to T triangles (the exact count is "
                     "printed); default 800 triangles (20 x 20) when neither is given")
          ->type_name("T")
          ->check(CLI::PositiveNumber);
  grid_option->excludes(triangles_option);
  app.add_option("--frames", frames, "Number of frames to write")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--fps", fps, "Frames per simulated second")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--substeps", substeps,
                 "Integration substeps per frame; 0 picks the fewest that are stable")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--first-frame", first_frame, "Number of the first frame's file")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("-o,--output-dir", output_dir, "Directory for the frames (created if missing)")
      ->capture_default_str();
  app.add_option("--prefix", prefix, "Frames are named PREFIX.%04d.obj")->capture_default_str();
  app.add_option("--decimals", decimals, "Digits after the point in the coordinates")
      ->capture_default_str()
      ->check(CLI::Range(0, 17));
  app.add_option("--seed", seed, "Seed of the initial jitter")->capture_default_str();
  app.add_option("--jitter", material.jitter,
                 "Initial position noise, as a fraction of the grid spacing")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--cloth-size", scene.cloth_size, "Side of the square cloth (m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--drop-height", scene.drop_height,
                 "Gap between the cloth and the top of the sphere at the start (m)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sphere-radius", scene.sphere_radius,
                 "Radius of the sphere (m), centred at the origin")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--ground", scene.ground, "Add a ground plane below the sphere");
  app.add_option("--ground-height", ground_height,
                 "Height of the ground plane (default: the bottom of the sphere)");
  app.add_option("--stretch", material.stretch_stiffness, "Structural spring stiffness (N/m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--shear", material.shear_stiffness, "Shear spring stiffness (N/m)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--bend", material.bend_stiffness, "Bending spring stiffness (N/m)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--damping", material.damping_ratio,
                 "Spring damping, as a fraction of critical damping")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--friction", material.friction, "Coulomb friction against sphere and ground")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--write-sphere", sphere_path,
                 "Also write the sphere as an obstacle OBJ to this path (outside the frames' "
                 "directory if that directory is read as a sequence)")
      ->type_name("PATH");
  app.add_option("--sphere-segments", sphere_segments, "Segments around the written sphere")
      ->capture_default_str()
      ->check(CLI::Range(4, 4096));
  app.add_option("--write-sphere-radius", write_sphere_radius,
                 "Radius of the written sphere (default: --sphere-radius); a larger one, same "
                 "centre, is an obstacle the cloth goes into")
      ->type_name("R")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", threads,
                 "OpenMP threads (0: OpenMP's default); the files do not depend on it")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "No progress on standard error");

  // Exit status as snag's: 0 done, 2 usage error, 1 anything else (I/O, unstable simulation).
  GridSize grid{20, 20};
  try {
    app.parse(argc, argv);
    if (!grid_text.empty()) {
      grid = parse_grid(grid_text);
    } else if (triangles > 0) {
      grid = snag::samples::grid_for_triangles(triangles);
    }
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;
  } catch (const std::invalid_argument& error) {
    std::cerr << "snag-cloth: " << error.what() << "\n";
    return 2;
  }

  try {
    const auto started = std::chrono::steady_clock::now();
    if (!std::isnan(ground_height)) {
      scene.ground_height = ground_height;
    } else {
      scene.ground_height = scene.sphere_center.y() - scene.sphere_radius;
    }
    if (threads > 0) {
      omp_set_num_threads(threads);
    }

    snag::samples::ClothSim sim(grid, scene, material, seed);
    const double frame_time = 1.0 / fps;
    const int stable = int(std::ceil(frame_time / sim.stable_substep()));
    if (substeps == 0) {
      substeps = stable;
    } else if (substeps < stable) {
      std::cerr << "snag-cloth: warning: " << substeps << " substeps per frame is below the "
                << stable << " that keep the integration stable\n";
    }
    const double dt = frame_time / substeps;

    std::cout << "grid " << grid.nx << " x " << grid.ny << ": " << grid.triangle_count()
              << " triangles, " << grid.vertex_count() << " vertices; " << frames
              << (frames == 1 ? " frame at " : " frames at ") << fps << " fps, " << substeps
              << " substeps per frame\n";

    const std::filesystem::path directory(output_dir);
    std::filesystem::create_directories(directory);
    const auto faces = snag::samples::grid_triangles(grid);
    const std::string settings = "grid " + std::to_string(grid.nx) + "x" + std::to_string(grid.ny) +
                                 ", " + std::to_string(grid.triangle_count()) +
                                 " triangles, seed " + std::to_string(seed);
    for (int f = 0; f < frames; ++f) {
      if (f > 0) {
        sim.advance(dt, substeps);
      }
      const int number = first_frame + f;
      if (!sim.positions().allFinite()) {
        throw std::runtime_error("the simulation diverged before frame " + std::to_string(number) +
                                 "; use more --substeps");
      }
      const std::vector<std::string> header{"snag-cloth: " + settings + ", frame " +
                                            std::to_string(number) +
                                            ", t = " + fixed(f * frame_time, 6) + " s"};
      snag::samples::write_obj(directory / frame_name(prefix, number), sim.positions(), faces,
                               decimals, header);
      if (!quiet) {
        std::cerr << "\rframe " << (f + 1) << "/" << frames << std::flush;
      }
    }
    if (!quiet) {
      std::cerr << "\n";
    }

    if (!sphere_path.empty()) {
      // Only the written mesh takes --write-sphere-radius; the simulation's sphere is unchanged.
      const double radius =
          std::isnan(write_sphere_radius) ? scene.sphere_radius : write_sphere_radius;
      const auto sphere = snag::samples::make_sphere(scene.sphere_center, radius, sphere_segments);
      const std::filesystem::path path(sphere_path);
      if (path.has_parent_path()) {
        std::filesystem::create_directories(path.parent_path());
      }
      snag::samples::write_obj(path, sphere.positions, sphere.triangles, decimals,
                               {"snag-cloth: sphere, radius " + fixed(radius, 6) + ", " +
                                std::to_string(sphere.triangles.size()) + " triangles"});
      std::cout << "sphere: " << sphere.triangles.size() << " triangles -> " << path.string()
                << "\n";
    }

    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::cout << "wrote " << frames << (frames == 1 ? " frame to " : " frames to ")
              << (directory / frame_name(prefix, first_frame)).string() << " .. "
              << frame_name(prefix, first_frame + frames - 1) << " in " << fixed(seconds, 2)
              << " s\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "snag-cloth: error: " << error.what() << "\n";
    return 1;
  }
}
