// The stress matrix: the cells of one run (options, the bunny and its Bullet shapes) and the
// scene families that add them, each family in its own file (impact_cells, pile_cells,
// range_cells, slope_cells, snapshot_cells). Internal to tools/stress.
#pragma once

#include "stress/snapshot_cells.hpp"
#include "stress/stress.hpp"
#include "stress/stress_worlds.hpp"

#include <cstdio>

namespace statsim::tools::stress {

// ---- the matrix -------------------------------------------------------------------------------------
class Matrix {
public:
  Matrix(const StressOptions& o, Body3 body, std::string meshes_dir)
      : opt_(o), body_(std::move(body)), shapes_(bench::make_bullet_shapes(body_)), dir_(std::move(meshes_dir))
  {
  }

  bool want(const std::string& m) const
  {
    return opt_.methods.empty() || std::find(opt_.methods.begin(), opt_.methods.end(), m) != opt_.methods.end();
  }
  std::vector<std::string> methods3() const
  {
    std::vector<std::string> r;
    for (const auto& m : kMethods3)
      if (want(m)) r.push_back(m);
    return r;
  }
  void add(const std::string& scene, const std::string& method, bool pass, const std::string& figure,
           const std::string& criterion)
  {
    cells_.push_back({scene, method, pass, figure, criterion});
    if (opt_.progress)
      std::fprintf(stderr, "stress: %-34s %-13s %s  %s\n", scene.c_str(), method.c_str(), pass ? "pass" : "FAIL",
                   figure.c_str());
  }
  std::vector<StressCell> take() { return std::move(cells_); }

  const Body3& body() const { return body_; }
  const StressOptions& opt() const { return opt_; }
  double R() const { return body_.bounding_radius; }
  double budget() const { return opt_.quick ? std::min(opt_.budget_s, 20.0) : opt_.budget_s; }

  void fast_impact();
  void large_time_step();
  void deep_pile();
  void energy();
  void out_of_range();
  void long_run();
  void bad_input();
  void slopes();
  void small_time_step();
  void mass_ratio();
  /// statsim only (snapshot_cells.cpp).
  void snapshot()
  {
    snapshot_cells(want("statistical"), want("statistical2d"), opt_.hull_contacts,
                   [this](const std::string& scene, const std::string& method, bool pass, const std::string& figure,
                          const std::string& criterion) { add(scene, method, pass, figure, criterion); });
  }
  void spawn_remove();
  void sizes();

  std::unique_ptr<bench::Sim> sim3(const std::string& method, const Setup3& setup,
                                   const std::vector<scenes::BodyState3>& states, double dt) const
  {
    return make_sim3(body_, shapes_, method, with_contacts(setup), states, dt);
  }
  Setup3 with_contacts(Setup3 setup) const
  {
    setup.body_contacts = contacts();
    setup.ground_hulls = ground_hulls();
    return setup;
  }
  bool ground_hulls() const { return opt_.ground_hulls; }
  BodyContacts contacts() const
  {
    return opt_.hull_contacts ? BodyContacts::automatic : BodyContacts::collision_spheres;
  }

private:
  StressOptions opt_;
  Body3 body_;
  std::shared_ptr<bench::BulletShapes> shapes_;
  std::string dir_;
  std::vector<StressCell> cells_;
};

/// A uniformly random rotation (a point of the unit 4-ball by rejection, normalised).
inline Eigen::Quaterniond random_q(scenes::SceneRng& rng)
{
  for (;;) {
    const Eigen::Vector4d p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const double n2 = p.squaredNorm();
    if (n2 > 1e-6 && n2 <= 1) return Eigen::Quaterniond(p[0], p[1], p[2], p[3]).normalized();
  }
}

}  // namespace statsim::tools::stress
