// Support code of the C++ tests: meshes built by CGAL and read by OpenMesh, results as plain
// arrays, and the CGAL-based reference checker. Handles and errors are the public
// voussoir.hpp's. Only support.cpp includes CGAL and OpenMesh (they are slow to compile);
// the tests include this header alone.
#pragma once

#include <voussoir.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace vsrt {

// ---------------------------------------------------------------------------------------------
// Problems and solutions as plain arrays (the C API's layouts).

struct MeshData {
    std::string name;
    std::vector<double> positions;    // #V by 3, row-major
    std::vector<uint32_t> triangles;  // #F by 3, row-major
    std::vector<uint32_t> anchored;   // support ids
    std::size_t n_vertices() const { return positions.size() / 3; }
    std::size_t n_faces() const { return triangles.size() / 3; }
};

voussoir::Mesh make_mesh(const MeshData &mesh);   // throws voussoir::Error

// Everything a result reports, read through voussoir::Result's getters.
struct Solution {
    VsrResultKind kind = VSR_RESULT_KIND_ANALYSIS;
    std::size_t n_vertices = 0, n_edges = 0, n_faces = 0, n_holes = 0;
    std::vector<double> positions;          // #V by 3
    std::vector<uint32_t> edges;            // #E by 2
    std::vector<double> force_densities;    // #E
    std::vector<double> weights;            // #V
    std::vector<double> airy;               // #V
    std::vector<double> loads;              // #V
    std::vector<double> external;           // #V by 2
    std::vector<double> residuals;          // #V   (the library's; never used as a reference)
    std::vector<double> imbalance;          // #V by 2 (idem)
    std::vector<double> holes;              // #H by 3
    std::vector<double> centres;            // #F by 2
    std::vector<double> segments;           // #S by 4
    std::vector<uint32_t> segment_edges;    // #S
    VsrStressStatus stress_status = VSR_STRESS_STATUS_NUMERICAL_ERROR;
    double eps_inf = 0, objective = 0;
    std::size_t qp_iterations = 0;
    // Form finding only.
    VsrTermination termination = VSR_TERMINATION_NUMERICAL_ERROR;
    std::size_t iterations = 0;
    std::string termination_message;
};

Solution read_solution(const voussoir::Result &result);   // throws voussoir::Error

enum class Solve { Analysis, FormFinding };
const char *to_string(Solve solve);

// Solves `mesh` with default settings (form finding: at most `max_iterations` iterations).
Solution solve(const MeshData &mesh, Solve how, std::size_t max_iterations = 50);

// ---------------------------------------------------------------------------------------------
// Meshes.

// Plan domains triangulated by CGAL (constrained Delaunay + Delaunay refinement, seeds in the
// holes), heights from analytic functions, supports on (parts of) the boundary.
std::vector<std::string> generated_names();
MeshData generated(const std::string &name);

// The shared OBJ models (../shared/data/models), read with OpenMesh; supports from the JSON
// sidecar. `models_available()` is false when the folder is absent; `models_required()` is
// true in CI (`CI` set, not 0 or false) or with VSR_REQUIRE_MODELS=1, where the tests that
// need the models fail instead of saying skipped.
std::vector<std::string> model_names();
bool models_available();
bool models_required();
std::string models_dir();
MeshData read_model(const std::string &name);
// Writes `mesh` with the positions `positions` (#V by 3) with OpenMesh into the build's
// output folder and returns the path; the extension chooses the format. OpenMesh 9 reads and
// writes OBJ (and PLY, OFF) through single-precision points whatever the mesh's point type;
// its native .om format keeps doubles. `read_mesh_file` reads positions and faces back.
std::string write_mesh_file(const MeshData &mesh, const std::vector<double> &positions,
                            const std::string &file_name);
MeshData read_mesh_file(const std::string &path);

// ---------------------------------------------------------------------------------------------
// The reference checker: recomputes everything from the mesh (triangles, supports), the
// returned positions, force densities, weights, external forces and hole coefficients, with
// CGAL's kernel. The library's residual, imbalance, centre and segment arrays are never used
// as the reference.

struct CheckOptions {
    // Vertical equilibrium: max |r_i| / mean p_i over non-anchored vertices must be below
    // this (form finding that converged: the solve's tolerance); < 0 checks only that the
    // recomputed ε∞ equals the one the library reports.
    double vertical_tolerance = -1.0;
    // Horizontal imbalance relative to the vertex's Σ_j |q_ij| l_ij + |P_i| + mean load: at
    // interior vertices it holds by construction (reduced formulation), at free boundary
    // vertices it is an equality constraint of the QP, met to the solver's accuracy.
    double horizontal_tolerance = 1e-9;
    double free_horizontal_tolerance = 1e-7;
    double dual_tolerance = 1e-9;         // relative to max |q| over interior edges
    double load_tolerance = 1e-12;        // relative to the largest load
    double density = 1.0;                 // the load rule: density × 3-D area / 3
};

struct CheckReport {
    std::vector<std::string> failures;    // empty when every check passed
    std::set<std::string> failed_checks;  // "dual", "holes", "regular", "vertical", ...
    bool failed(const std::string &check) const { return failed_checks.count(check) != 0; }
    // Counts and worst values (for the test log).
    std::size_t non_anchored = 0, interior_edges = 0, dual_checked = 0, dual_skipped_cut = 0;
    std::size_t regular_checked = 0, hidden_vertices = 0, cut_faces = 0, cut_faces_explained = 0;
    bool all_positive = false, holes_zero = true, regular_applies = false;
    std::string regular_note;             // why (b) was or was not applied
    double eps_inf = 0, eps_inf_reported = 0, max_horizontal = 0, max_horizontal_free = 0;
    double max_dual = 0, max_closure = 0, max_load = 0;
    double max_residual_vs_library = 0, min_q_ratio = 0;
    bool ok() const { return failures.empty(); }
    std::string summary() const;
};

CheckReport reference_check(const MeshData &mesh, const Solution &solution,
                            const CheckOptions &options);

// The undirected edges of `mesh` (smaller id first), sorted: the order of the library's
// per-edge arrays.
std::vector<std::array<uint32_t, 2>> sorted_edges(const MeshData &mesh);

}  // namespace vsrt
