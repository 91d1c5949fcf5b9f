#include "cloth_sim.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace snag::samples {
namespace {

// A uniform double in [-1, 1) from the raw 64-bit output: std::uniform_real_distribution is not
// specified bit for bit, and the generated files must be the same with every standard library.
double symmetric_unit(std::mt19937_64& rng) {
  return double(rng() >> 11) * 0x1.0p-52 - 1.0;
}

// Keeps particle `x` out of the half-space or ball whose outward normal at the contact is `n`
// (unit), `depth` being how far inside it is; removes the inward velocity and applies Coulomb
// friction, i.e. the tangential speed drops by at most `friction` times the normal speed removed.
void resolve_contact(Eigen::Ref<Eigen::Vector3d> x, Eigen::Ref<Eigen::Vector3d> v,
                     const Eigen::Vector3d& n, double depth, double friction) {
  x += depth * n;
  const double vn = v.dot(n);
  if (vn >= 0.0) {
    return;
  }
  v -= vn * n;
  const double vt = v.norm();
  if (vt > 0.0) {
    v *= std::max(0.0, 1.0 - friction * (-vn) / vt);
  }
}

}  // namespace

ClothSim::ClothSim(GridSize grid, const SceneParams& scene, const MaterialParams& material,
                   std::uint64_t seed)
    : grid_(grid), scene_(scene), material_(material) {
  if (grid.nx < 1 || grid.ny < 1) {
    throw std::invalid_argument("the grid needs at least 1 x 1 quads");
  }
  const int n = int(grid.vertex_count());
  mass_ = material.density * scene.cloth_size * scene.cloth_size / n;

  // Rest state: flat, horizontal, rotated about y and offset from the sphere's axis so that the
  // drape is not symmetric; the jitter (seeded) only perturbs the first frame's positions.
  const double angle = scene.cloth_rotation_deg * std::numbers::pi / 180.0;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d centre =
      scene.sphere_center + Eigen::Vector3d(scene.cloth_offset.x(),
                                            scene.sphere_radius + scene.drop_height,
                                            scene.cloth_offset.y());
  const double hx = scene.cloth_size / grid.nx;
  const double hz = scene.cloth_size / grid.ny;
  Eigen::Matrix3Xd rest(3, n);
  for (int j = 0; j <= grid.ny; ++j) {
    for (int i = 0; i <= grid.nx; ++i) {
      const Eigen::Vector3d local(i * hx - 0.5 * scene.cloth_size, 0.0,
                                  j * hz - 0.5 * scene.cloth_size);
      rest.col(grid.vertex(i, j)) = centre + rotation * local;
    }
  }
  x_ = rest;
  std::mt19937_64 rng(seed);
  const double jitter = material.jitter * std::min(hx, hz);
  for (int p = 0; p < n; ++p) {
    // Three draws per particle in a fixed order, so the stream does not depend on anything else.
    const double dx = symmetric_unit(rng);
    const double dy = symmetric_unit(rng);
    const double dz = symmetric_unit(rng);
    x_.col(p) += jitter * Eigen::Vector3d(dx, dy, dz);
  }
  v_ = Eigen::Matrix3Xd::Zero(3, n);
  a_ = Eigen::Matrix3Xd::Zero(3, n);

  // Springs, each stored at both ends. Damping is a fraction of the critical damping of two
  // particles of mass m joined by the spring (reduced mass m / 2).
  std::vector<std::vector<SpringEnd>> ends(std::size_t(n), std::vector<SpringEnd>{});
  const auto add = [&](int a, int b, double stiffness) {
    const double length = (rest.col(a) - rest.col(b)).norm();
    const double damping = material.damping_ratio * 2.0 * std::sqrt(stiffness * mass_ / 2.0);
    ends[std::size_t(a)].push_back({b, length, stiffness, damping});
    ends[std::size_t(b)].push_back({a, length, stiffness, damping});
  };
  for (int j = 0; j <= grid.ny; ++j) {
    for (int i = 0; i <= grid.nx; ++i) {
      const int p = grid.vertex(i, j);
      if (i + 1 <= grid.nx) add(p, grid.vertex(i + 1, j), material.stretch_stiffness);
      if (j + 1 <= grid.ny) add(p, grid.vertex(i, j + 1), material.stretch_stiffness);
      if (i + 1 <= grid.nx && j + 1 <= grid.ny) {
        add(p, grid.vertex(i + 1, j + 1), material.shear_stiffness);
        add(grid.vertex(i + 1, j), grid.vertex(i, j + 1), material.shear_stiffness);
      }
      if (i + 2 <= grid.nx) add(p, grid.vertex(i + 2, j), material.bend_stiffness);
      if (j + 2 <= grid.ny) add(p, grid.vertex(i, j + 2), material.bend_stiffness);
    }
  }
  spring_begin_.assign(std::size_t(n) + 1, 0);
  double max_stiffness_sum = 0.0;
  for (int p = 0; p < n; ++p) {
    spring_begin_[std::size_t(p) + 1] =
        spring_begin_[std::size_t(p)] + int(ends[std::size_t(p)].size());
    double sum = 0.0;
    for (const SpringEnd& end : ends[std::size_t(p)]) {
      springs_.push_back(end);
      sum += end.stiffness;
    }
    max_stiffness_sum = std::max(max_stiffness_sum, sum);
  }
  // Gershgorin: the stiffness matrix's eigenvalues are at most 2 * the largest row sum, so the
  // highest frequency is at most sqrt(2 K / m); symplectic Euler is stable below dt = 2 / omega
  // = sqrt(2 m / K). 0.7 sqrt(m / K) leaves a factor of 2 for the damping terms and contacts.
  stable_substep_ = 0.7 * std::sqrt(mass_ / max_stiffness_sum);
}

void ClothSim::advance(double dt, int substeps) {
  for (int s = 0; s < substeps; ++s) {
    substep(dt);
  }
}

void ClothSim::substep(double dt) {
  const int n = int(x_.cols());
  const Eigen::Vector3d gravity(0.0, -9.81, 0.0);
  const double inverse_mass = 1.0 / mass_;

  // Forces: each particle reads the state and writes only its own acceleration.
#pragma omp parallel for schedule(static)
  for (int p = 0; p < n; ++p) {
    const Eigen::Vector3d xp = x_.col(p);
    const Eigen::Vector3d vp = v_.col(p);
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (int e = spring_begin_[std::size_t(p)]; e < spring_begin_[std::size_t(p) + 1]; ++e) {
      const SpringEnd& end = springs_[std::size_t(e)];
      const Eigen::Vector3d d = x_.col(end.other) - xp;
      const double length = d.norm();
      if (length <= 0.0) {
        continue;  // coincident particles: no direction to pull along
      }
      const Eigen::Vector3d dir = d * (1.0 / length);
      const double relative_speed = (v_.col(end.other) - vp).dot(dir);
      force += (end.stiffness * (length - end.rest) + end.damping * relative_speed) * dir;
    }
    a_.col(p) = force * inverse_mass + gravity - material_.air_drag * vp;
  }

  // Integration and contacts: again one particle per iteration, no shared writes.
  const Eigen::Vector3d centre = scene_.sphere_center;
  const double radius = scene_.sphere_radius + material_.contact_offset;
  const double floor = scene_.ground_height + material_.contact_offset;
#pragma omp parallel for schedule(static)
  for (int p = 0; p < n; ++p) {
    auto v = v_.col(p);
    auto x = x_.col(p);
    v += dt * a_.col(p);
    x += dt * v;
    const Eigen::Vector3d r = x - centre;
    const double distance = r.norm();
    if (distance < radius) {
      const Eigen::Vector3d normal =
          distance > 0.0 ? Eigen::Vector3d(r / distance) : Eigen::Vector3d::UnitY();
      resolve_contact(x, v, normal, radius - distance, material_.friction);
    }
    if (scene_.ground && x.y() < floor) {
      resolve_contact(x, v, Eigen::Vector3d::UnitY(), floor - x.y(), material_.friction);
    }
  }
}

}  // namespace snag::samples
