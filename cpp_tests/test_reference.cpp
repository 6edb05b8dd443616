// The CGAL-based reference check (issue 5) on meshes built by CGAL and on the shared models
// read by OpenMesh, under stress analysis and form finding. Each test solves through the
// installed C API and checks the outputs with vsrt::reference_check (support.cpp): vertical
// and horizontal equilibrium recomputed with CGAL vectors, loads from the 3-D areas, q = d*/l
// from CGAL power centres of the returned weights, and the regular triangulation.
//
// Holes: where the returned hole coefficients are ~0 (every mesh whose holes have free rims),
// (a) is checked on every interior edge and (b) applies. Where they are not (annular_vault,
// free_vault, four_holes, hex, three_pillar, cheese: holes with anchored vertices) the Airy
// function is multivalued: (a) is checked directly on the edges whose two faces are away
// from the hole cuts (with one hole, the faces along its cut must be explained by the
// returned jump c_h, see support.cpp), and (b) is not applied. Each test prints which.
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace {

using vsrt::CheckOptions;
using vsrt::MeshData;
using vsrt::Solution;
using vsrt::Solve;

constexpr double kTolerance = 1e-6;   // the default form-finding tolerance on eps_inf

void print(const MeshData &mesh, const Solution &s, Solve how, const vsrt::CheckReport &rep) {
    static const char *const status[] = {"solved", "almost solved", "infeasible",
                                         "max iterations", "numerical error"};
    std::printf("%s, %s: V %zu, E %zu, F %zu, holes %zu, supports %zu; stress %s after %zu QP "
                "iterations",
                mesh.name.c_str(), vsrt::to_string(how), s.n_vertices, s.n_edges, s.n_faces,
                s.n_holes, mesh.anchored.size(),
                s.stress_status <= VSR_STRESS_STATUS_NUMERICAL_ERROR ? status[s.stress_status] : "?",
                s.qp_iterations);
    if (how == Solve::FormFinding)
        std::printf("; %s after %zu iterations", s.termination_message.c_str(), s.iterations);
    std::printf("\n  %s\n", rep.summary().c_str());
    for (std::size_t h = 0; h < s.holes.size() / 3; ++h)
        std::printf("  hole %zu: c = %.6e, a = (%.3e, %.3e)\n", h, s.holes[3 * h],
                    s.holes[3 * h + 1], s.holes[3 * h + 2]);
}

// Solves and checks; returns the solution for further checks.
Solution solve_and_check(const MeshData &mesh, Solve how) {
    const Solution s = vsrt::solve(mesh, how);
    CheckOptions options;
    if (how == Solve::FormFinding) {
        EXPECT_EQ(s.termination, VSR_TERMINATION_CONVERGED) << s.termination_message;
        options.vertical_tolerance = kTolerance;
    }
    EXPECT_TRUE(s.stress_status == VSR_STRESS_STATUS_SOLVED ||
                s.stress_status == VSR_STRESS_STATUS_ALMOST_SOLVED)
        << "stress status " << s.stress_status;
    const vsrt::CheckReport rep = vsrt::reference_check(mesh, s, options);
    print(mesh, s, how, rep);
    EXPECT_TRUE(rep.ok()) << rep.summary();
    // (a) covers every interior edge without hole stress, and (b) is applied there (with the
    // default q_min > 0 every interior q is positive).
    if (rep.holes_zero) {
        EXPECT_EQ(rep.dual_checked, rep.interior_edges);
        EXPECT_TRUE(rep.regular_applies) << rep.regular_note;
    }
    return s;
}

// Writes the form-found shape with OpenMesh and reads it back. The .om file (OpenMesh's native
// format, double precision) must give the positions to the last bit, and the reference check
// passes on the positions read from it. The .obj file goes through OpenMesh 9's
// single-precision OBJ exporter: its coordinates are the form-found ones rounded to float (printed with 17
// decimals), and
// the equilibrium error this rounding causes is printed.
void write_back_and_recheck(const MeshData &mesh, const Solution &s) {
    const std::string om = vsrt::write_mesh_file(mesh, s.positions, mesh.name + "_formfound.om");
    const MeshData exact = vsrt::read_mesh_file(om);
    ASSERT_EQ(exact.triangles, mesh.triangles) << om;
    ASSERT_EQ(exact.positions, s.positions) << om;
    Solution from_file = s;
    from_file.positions = exact.positions;
    CheckOptions options;
    options.vertical_tolerance = kTolerance;
    const vsrt::CheckReport rep = vsrt::reference_check(mesh, from_file, options);
    EXPECT_TRUE(rep.ok()) << om << ": " << rep.summary();

    const std::string obj = vsrt::write_mesh_file(mesh, s.positions, mesh.name + "_formfound.obj");
    const MeshData single = vsrt::read_mesh_file(obj);
    ASSERT_EQ(single.triangles, mesh.triangles) << obj;
    ASSERT_EQ(single.positions.size(), s.positions.size()) << obj;
    for (std::size_t i = 0; i < s.positions.size(); ++i)   // float rounding, 17 decimals
        ASSERT_NEAR(single.positions[i], s.positions[i], 6e-8 * std::abs(s.positions[i]) + 1e-16)
            << obj << ": coordinate " << i;
    from_file.positions = single.positions;
    options.vertical_tolerance = -1;
    options.load_tolerance = 1e-6;
    const vsrt::CheckReport rounded = vsrt::reference_check(mesh, from_file, options);
    std::printf("  wrote %s (exact) and %s (float coordinates: eps_inf %.3e there)\n", om.c_str(),
                obj.c_str(), rounded.eps_inf);
}

// ---------------------------------------------------------------------------------------------

class Generated : public ::testing::TestWithParam<std::string> {};

TEST_P(Generated, Analysis) {
    const MeshData mesh = vsrt::generated(GetParam());
    solve_and_check(mesh, Solve::Analysis);
}

TEST_P(Generated, FormFinding) {
    const MeshData mesh = vsrt::generated(GetParam());
    const Solution s = solve_and_check(mesh, Solve::FormFinding);
    write_back_and_recheck(mesh, s);
}

INSTANTIATE_TEST_SUITE_P(Cgal, Generated, ::testing::ValuesIn(vsrt::generated_names()),
                         [](const auto &info) { return info.param; });

// ---------------------------------------------------------------------------------------------

class Model : public ::testing::TestWithParam<std::string> {
  protected:
    void SetUp() override {
        if (!vsrt::models_available()) {
            if (vsrt::models_required())
                FAIL() << vsrt::models_dir()
                       << " not found, and CI or VSR_REQUIRE_MODELS=1 requires it";
            GTEST_SKIP() << "skipped: " << vsrt::models_dir() << " not found";
        }
    }
};

TEST_P(Model, Analysis) {
    const MeshData mesh = vsrt::read_model(GetParam());
    solve_and_check(mesh, Solve::Analysis);
}

TEST_P(Model, FormFinding) {
    const MeshData mesh = vsrt::read_model(GetParam());
    const Solution s = solve_and_check(mesh, Solve::FormFinding);
    write_back_and_recheck(mesh, s);
}

INSTANTIATE_TEST_SUITE_P(OpenMesh, Model, ::testing::ValuesIn(vsrt::model_names()),
                         [](const auto &info) { return info.param; });

}  // namespace
