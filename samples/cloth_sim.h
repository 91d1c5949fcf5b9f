// A mass-spring cloth dropped over a sphere, with no self-collision response.
//
// Model (units: metres, kilograms, seconds; y is up):
// - one particle per grid vertex, all of equal mass (density * area / vertex count);
// - springs between grid neighbours: structural (i+1 and j+1), shear (both diagonals of every
//   quad) and bending (i+2 and j+2); each pulls with k * (length - rest) along its direction and
//   damps the relative velocity along that direction;
// - gravity and a mass-proportional air drag;
// - semi-implicit (symplectic) Euler substeps;
// - contact with the sphere (and, if enabled, a ground plane) by projecting particles out to the
//   surface plus a small offset, cancelling the inward velocity and applying Coulomb friction.
// The cloth never sees itself, so where it folds the layers pass through each other: that is the
// point of the generator, which makes test sequences for the self-intersection finder.
#pragma once

#include "cloth_grid.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace snag::samples {

struct SceneParams {
  double cloth_size = 2.0;   // side of the square cloth
  double drop_height = 0.5;  // gap between the cloth and the top of the sphere at t = 0
  Eigen::Vector2d cloth_offset{0.15, 0.1};  // (x, z) of the cloth centre relative to the sphere's
  double cloth_rotation_deg = 20.0;  // rotation of the cloth about y (breaks the grid's symmetry)
  Eigen::Vector3d sphere_center{0.0, 0.0, 0.0};
  double sphere_radius = 0.5;
  bool ground = false;  // a plane y = ground_height below the sphere
  double ground_height = -0.5;
};

struct MaterialParams {
  double density = 0.1;             // kg / m^2
  double stretch_stiffness = 60.0;  // N / m, structural springs. Independent of the resolution:
                                    // under a tension of T N/m each spring of a row carries T h
                                    // and stretches by T h / k, a strain of T / k for any h.
  double shear_stiffness = 20.0;    // N / m
  double bend_stiffness = 0.1;      // N / m, weak so that the cloth folds readily
  double damping_ratio = 0.02;      // spring damping as a fraction of critical damping
  double air_drag = 0.3;            // 1 / s
  double friction = 0.5;            // Coulomb coefficient against the sphere and the ground
  double contact_offset = 0.01;     // particles are kept this far outside the obstacles
  double jitter = 0.02;             // initial position noise, as a fraction of the grid spacing
};

class ClothSim {
 public:
  // Lays the cloth flat and horizontal above the sphere; `seed` drives the initial jitter only.
  ClothSim(GridSize grid, const SceneParams& scene, const MaterialParams& material,
           std::uint64_t seed);

  // The largest substep for which the explicit integration is stable, with a safety factor:
  // 0.7 sqrt(m / sum of the stiffnesses at one particle).
  [[nodiscard]] double stable_substep() const { return stable_substep_; }

  // Advances the simulation by `substeps` steps of `dt` seconds each. The result depends only on
  // the inputs, not on the number of OpenMP threads: every particle gathers its own forces in a
  // fixed order and no value is summed across threads.
  void advance(double dt, int substeps);

  // 3 x vertex_count positions, column v is vertex v of the grid (see cloth_grid.h).
  [[nodiscard]] const Eigen::Matrix3Xd& positions() const { return x_; }
  [[nodiscard]] GridSize grid() const { return grid_; }

 private:
  void substep(double dt);

  GridSize grid_;
  SceneParams scene_;
  MaterialParams material_;
  double mass_ = 0.0;
  double stable_substep_ = 0.0;
  Eigen::Matrix3Xd x_;  // positions
  Eigen::Matrix3Xd v_;  // velocities
  Eigen::Matrix3Xd a_;  // accelerations of the current substep

  // Springs stored once per endpoint, grouped by particle (compressed rows): particle p's springs
  // are entries spring_begin_[p] .. spring_begin_[p + 1] - 1, so a particle sums its own forces
  // without atomics. 32 bytes per entry.
  struct SpringEnd {
    int other;         // the particle at the other end
    double rest;       // rest length
    double stiffness;  // N / m
    double damping;    // N s / m
  };
  std::vector<int> spring_begin_;
  std::vector<SpringEnd> springs_;
};

}  // namespace snag::samples
