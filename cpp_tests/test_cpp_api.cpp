// The C++ API (voussoir.hpp): each hostile input of the C table throws voussoir::Error with
// the C call's status and exact message (and the try_ twin returns that status); Mesh,
// Settings and Result move without double frees (ASan build); results equal the C API's bit
// for bit; getters into caller storage; the progress std::function cancels and carries
// exceptions out; concurrent solves on shared const objects; the assessment classes
// (Envelope, AssessSettings, Assessment) equal the C API bit for bit and throw its statuses.
#include "support.hpp"

#include <voussoir.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

// The square of tests/c/hostile.c: 4 triangles around a raised centre, corners anchored.
const std::vector<double> kPositions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3};
const std::vector<uint32_t> kTriangles = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
const std::vector<uint32_t> kAnchored = {0, 1, 2, 3};
const double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
bool same_bits(const std::vector<T> &a, const std::vector<T> &b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// ---------------------------------------------------------------------------------------------
// The hostile-input table through the C++ API.

struct HostileCase {
    const char *name;
    std::function<VsrStatus()> c_call;    // the C API with the same input
    std::function<void()> cpp_call;       // must throw voussoir::Error
    std::function<VsrStatus()> try_call;  // the try_ twin (may be empty)
};

void PrintTo(const HostileCase &c, std::ostream *os) { *os << c.name; }

std::vector<double> with(std::vector<double> v, std::size_t i, double x) {
    v[i] = x;
    return v;
}
std::vector<uint32_t> with(std::vector<uint32_t> v, std::size_t i, uint32_t x) {
    v[i] = x;
    return v;
}

HostileCase mesh_case(const char *name, std::vector<double> p, std::vector<uint32_t> t,
                      std::vector<uint32_t> a) {
    return {name,
            [=] {
                VsrMesh *out = nullptr;
                return vsr_mesh_create(p.data(), p.size() / 3, t.data(), t.size() / 3, a.data(),
                                       a.size(), &out);
            },
            [=] { voussoir::Mesh mesh(p, t, a); },
            [=] {
                voussoir::Mesh out;
                return voussoir::Mesh::try_create(p.data(), p.size() / 3, t.data(), t.size() / 3,
                                                  a.data(), a.size(), out);
            }};
}

// A settings setter: `c` on fresh C settings, `cpp` on fresh voussoir::Settings.
HostileCase settings_case(const char *name, std::function<VsrStatus(VsrSettings *)> c,
                          std::function<void(voussoir::Settings &)> cpp,
                          std::function<VsrStatus(voussoir::Settings &)> try_cpp) {
    return {name,
            [=] {
                voussoir::Settings s;
                return c(s.get());
            },
            [=] {
                voussoir::Settings s;
                cpp(s);
            },
            [=] {
                voussoir::Settings s;
                return try_cpp(s);
            }};
}

#define VSR_SETTER_CASE(setter, ...)                                                       \
    settings_case(                                                                         \
        #setter, [](VsrSettings *s) { return vsr_settings_set_##setter(s, __VA_ARGS__); }, \
        [](voussoir::Settings &s) { s.setter(__VA_ARGS__); },                              \
        [](voussoir::Settings &s) { return s.try_##setter(__VA_ARGS__); })

// A mesh setter on the square.
HostileCase mesh_setter_case(const char *name, std::function<VsrStatus(VsrMesh *)> c,
                             std::function<void(voussoir::Mesh &)> cpp,
                             std::function<VsrStatus(voussoir::Mesh &)> try_cpp) {
    auto square = [] { return voussoir::Mesh(kPositions, kTriangles, kAnchored); };
    return {name,
            [=] {
                voussoir::Mesh m = square();
                return c(m.get());
            },
            [=] {
                voussoir::Mesh m = square();
                cpp(m);
            },
            [=] {
                voussoir::Mesh m = square();
                return try_cpp(m);
            }};
}

std::vector<HostileCase> hostile_cases() {
    const auto &p = kPositions;
    const auto &t = kTriangles;
    const auto &a = kAnchored;
    std::vector<double> stacked = p;
    for (std::size_t i = 0; i < p.size(); ++i) stacked.push_back(p[i] + (i % 3 == 2 ? 1.0 : 0.5));
    std::vector<uint32_t> stacked_t = t;
    for (uint32_t v : t) stacked_t.push_back(v + 5);
    std::vector<double> huge = p;
    for (double &c : huge) c *= 1e200;
    const std::vector<double> nan4(4, kNaN), nan5(5, kNaN), ones3(3, 1.0), neg5(5, -1.0);
    const std::vector<uint32_t> boundary_pair = {0, 1}, far_pair = {0, 9};
    const std::vector<double> zeros4(4, 0.0);
    std::vector<HostileCase> cases = {
        mesh_case("mesh_empty", {}, t, a),
        mesh_case("mesh_index_out_of_range", p, with(t, 5, 5u), a),
        mesh_case("mesh_anchor_out_of_range", p, t, {0, 1, 2, 99}),
        mesh_case("mesh_anchor_twice", p, t, {0, 1, 2, 2}),
        mesh_case("mesh_nan_coordinate", with(p, 13, kNaN), t, a),
        mesh_case("mesh_infinite_coordinate", with(p, 3, INFINITY), t, a),
        mesh_case("mesh_repeated_vertex", p, with(t, 2, t[1]), a),
        mesh_case("mesh_zero_area_face", with(with(p, 12, 0.5), 13, 0.0), t, a),
        mesh_case("mesh_no_support", p, t, {}),
        mesh_case("mesh_stacked_in_plan", stacked, stacked_t, {0, 1, 2, 3, 5, 6, 7, 8}),
        mesh_case("mesh_coordinates_1e200", huge, t, a),
        VSR_SETTER_CASE(tolerance, kNaN),
        VSR_SETTER_CASE(tolerance, -1.0),
        VSR_SETTER_CASE(max_iterations, 0),
        VSR_SETTER_CASE(stall_window, 0),
        VSR_SETTER_CASE(q_min, -0.5, VSR_BOUND_KIND_ABSOLUTE),
        VSR_SETTER_CASE(q_min, 0.1, static_cast<VsrBoundKind>(7)),
        VSR_SETTER_CASE(q_min_scope, static_cast<VsrEdgeScope>(42)),
        VSR_SETTER_CASE(q_max, 0.0, VSR_BOUND_KIND_RELATIVE),
        VSR_SETTER_CASE(q_max, 0.01, VSR_BOUND_KIND_RELATIVE),
        VSR_SETTER_CASE(tau_mode, static_cast<VsrTauMode>(42)),
        VSR_SETTER_CASE(hole_mode, static_cast<VsrHoleMode>(42)),
        VSR_SETTER_CASE(method, static_cast<VsrMethod>(42)),
        VSR_SETTER_CASE(fairness, -1.0),
        VSR_SETTER_CASE(max_height_change, 0.0),
        VSR_SETTER_CASE(load_rule, static_cast<VsrLoadRule>(42)),
        VSR_SETTER_CASE(formulation, static_cast<VsrFormulation>(42)),
        VSR_SETTER_CASE(qp_solver, static_cast<VsrQpSolver>(42)),
        VSR_SETTER_CASE(regularisation, kNaN),
        VSR_SETTER_CASE(dual_length_bounds, -1.0, 1.0),
        VSR_SETTER_CASE(dual_length_smoothing, 1.0, 1.5),
        VSR_SETTER_CASE(schedule_mu0, -1.0),
        VSR_SETTER_CASE(schedule_beta, 2.0),
        VSR_SETTER_CASE(schedule_mu_min, kNaN),
        VSR_SETTER_CASE(schedule_eta, 0.0),
        VSR_SETTER_CASE(schedule_pull, -1.0),
        VSR_SETTER_CASE(proximal_weight, -1.0),
        mesh_setter_case(
            "face_density_nan",
            [=](VsrMesh *m) { return vsr_mesh_set_face_density(m, nan4.data(), 4); },
            [=](voussoir::Mesh &m) { m.face_density(nan4); },
            [=](voussoir::Mesh &m) { return m.try_face_density(nan4.data(), 4); }),
        mesh_setter_case(
            "face_density_count",
            [=](VsrMesh *m) { return vsr_mesh_set_face_density(m, ones3.data(), 3); },
            [=](voussoir::Mesh &m) { m.face_density(ones3); },
            [=](voussoir::Mesh &m) { return m.try_face_density(ones3.data(), 3); }),
        mesh_setter_case(
            "extra_loads_nan",
            [=](VsrMesh *m) { return vsr_mesh_set_extra_loads(m, nan5.data(), 5); },
            [=](voussoir::Mesh &m) { m.extra_loads(nan5); },
            [=](voussoir::Mesh &m) { return m.try_extra_loads(nan5.data(), 5); }),
        mesh_setter_case(
            "horizontal_forces_count",
            [=](VsrMesh *m) { return vsr_mesh_set_horizontal_forces(m, ones3.data(), 1); },
            [=](voussoir::Mesh &m) {
                m.horizontal_forces({1.0, 1.0});
            },
            [=](voussoir::Mesh &m) { return m.try_horizontal_forces(ones3.data(), 1); }),
        mesh_setter_case(
            "prescribed_tau_negative",
            [=](VsrMesh *m) { return vsr_mesh_set_prescribed_tau(m, neg5.data(), 5); },
            [=](voussoir::Mesh &m) { m.prescribed_tau(neg5); },
            [=](voussoir::Mesh &m) { return m.try_prescribed_tau(neg5.data(), 5); }),
        mesh_setter_case(
            "polygon_diagonals_boundary_edge",
            [=](VsrMesh *m) { return vsr_mesh_set_polygon_diagonals(m, boundary_pair.data(), 1); },
            [=](voussoir::Mesh &m) { m.set_polygon_diagonals(boundary_pair); },
            [=](voussoir::Mesh &m) {
                return m.try_set_polygon_diagonals(boundary_pair.data(), 1);
            }),
        mesh_setter_case(
            "polygon_diagonals_out_of_range",
            [=](VsrMesh *m) { return vsr_mesh_set_polygon_diagonals(m, far_pair.data(), 1); },
            [=](voussoir::Mesh &m) { m.set_polygon_diagonals(far_pair); },
            [=](voussoir::Mesh &m) { return m.try_set_polygon_diagonals(far_pair.data(), 1); }),
        mesh_setter_case(
            "analyse_zero_loads",
            [=](VsrMesh *m) {
                VsrSettings *s = nullptr;
                VsrResult *r = nullptr;
                (void)vsr_settings_create(&s);
                (void)vsr_mesh_set_face_density(m, zeros4.data(), 4);
                const VsrStatus status = vsr_analyse(m, s, &r);
                vsr_settings_destroy(s);
                return status;
            },
            [=](voussoir::Mesh &m) { (void)voussoir::analyse(m.face_density(zeros4)); },
            [=](voussoir::Mesh &m) {
                voussoir::Result r;
                voussoir::check(m.try_face_density(zeros4.data(), 4));
                return voussoir::try_analyse(m, voussoir::Settings(), r);
            }),
        mesh_setter_case(
            "form_find_zero_loads",
            [=](VsrMesh *m) {
                VsrSettings *s = nullptr;
                VsrResult *r = nullptr;
                (void)vsr_settings_create(&s);
                (void)vsr_mesh_set_face_density(m, zeros4.data(), 4);
                const VsrStatus status = vsr_form_find(m, s, &r);
                vsr_settings_destroy(s);
                return status;
            },
            [=](voussoir::Mesh &m) { (void)voussoir::form_find(m.face_density(zeros4)); },
            [=](voussoir::Mesh &m) {
                voussoir::Result r;
                voussoir::check(m.try_face_density(zeros4.data(), 4));
                return voussoir::try_form_find(m, voussoir::Settings(), r);
            }),
        {"read_missing_file",
         [] {
             VsrMesh *out = nullptr;
             return vsr_mesh_read("vsr_cpp_missing.obj", nullptr, nullptr, 0, 1e-9, 1e-4, nullptr,
                                  &out);
         },
         [] { (void)voussoir::Mesh::read("vsr_cpp_missing.obj"); },
         [] {
             voussoir::Mesh out;
             return voussoir::Mesh::try_read("vsr_cpp_missing.obj", voussoir::ReadOptions(), out);
         }},
        {"read_bad_weld_tolerance",
         [] {
             VsrMesh *out = nullptr;
             return vsr_mesh_read("vsr_cpp_missing.off", nullptr, nullptr, 0, kNaN, 1e-4, nullptr,
                                  &out);
         },
         [] {
             voussoir::ReadOptions o;
             o.weld_tolerance = kNaN;
             (void)voussoir::Mesh::read("vsr_cpp_missing.off", o);
         },
         [] {
             voussoir::ReadOptions o;
             o.weld_tolerance = kNaN;
             voussoir::Mesh out;
             return voussoir::Mesh::try_read("vsr_cpp_missing.off", o, out);
         }},
        // Empty (moved-from) objects reach the C API as NULL handles.
        {"empty_mesh_counts",
         [] {
             std::size_t v, e, f, h;
             return vsr_mesh_counts(nullptr, &v, &e, &f, &h);
         },
         [] { (void)voussoir::Mesh().counts(); }, nullptr},
        {"empty_result_positions",
         [] { return vsr_result_positions(nullptr, nullptr, 0, nullptr); },
         [] { (void)voussoir::Result().positions(); },
         [] { return voussoir::Result().try_positions(nullptr, 0, nullptr); }},
    };
    return cases;
}

#undef VSR_SETTER_CASE

class Hostile : public ::testing::TestWithParam<HostileCase> {};

TEST_P(Hostile, ThrowsTheCStatusAndExactMessage) {
    const HostileCase &c = GetParam();
    const VsrStatus want = c.c_call();
    ASSERT_NE(want, VSR_STATUS_OK);
    const std::string message = vsr_last_error_message();
    ASSERT_FALSE(message.empty());
    try {
        c.cpp_call();
        FAIL() << "no exception; the C call gave " << vsr_status_name(want) << ": " << message;
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), want) << vsr_status_name(e.status()) << ": " << e.message();
        EXPECT_EQ(e.message(), message);
        EXPECT_EQ(std::string(e.what()), std::string(vsr_status_name(want)) + ": " + message);
    }
    if (c.try_call) {
        EXPECT_EQ(c.try_call(), want);
        EXPECT_EQ(std::string(voussoir::last_error_message()), message);
    }
}

INSTANTIATE_TEST_SUITE_P(CppApi, Hostile, ::testing::ValuesIn(hostile_cases()),
                         [](const auto &info) {
                             return std::string(info.param.name) + "_" + std::to_string(info.index);
                         });

TEST(CppApi, ShortCallerBufferThrowsBufferTooSmall) {
    const voussoir::Result result =
        voussoir::analyse(voussoir::Mesh(kPositions, kTriangles, kAnchored));
    double buffer[14];
    std::size_t needed = 0;
    ASSERT_EQ(vsr_result_positions(result.get(), buffer, 14, &needed), VSR_STATUS_BUFFER_TOO_SMALL);
    const std::string message = vsr_last_error_message();
    try {
        (void)result.positions(buffer, 14);
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_BUFFER_TOO_SMALL);
        EXPECT_EQ(e.message(), message);
    }
    // Analysis results have no form-finding outcome.
    EXPECT_THROW((void)result.termination(), voussoir::Error);
    ASSERT_EQ(vsr_result_eps_history(result.get(), nullptr, 0, nullptr), VSR_STATUS_NOT_AVAILABLE);
    const std::string not_available = vsr_last_error_message();
    try {
        (void)result.eps_history();
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_NOT_AVAILABLE);
        EXPECT_EQ(e.message(), not_available);
    }
}

TEST(CppApi, RowCountsAreCheckedBeforeTheCCall) {
    try {
        voussoir::Mesh mesh({0, 0, 0, 1}, kTriangles, kAnchored);
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_INVALID_ARGUMENT);
        EXPECT_EQ(e.message(), "`positions` has 4 values, not 3 per row");
    }
}

// ---------------------------------------------------------------------------------------------
// Ownership and moves (the ASan build catches double frees and, where it runs, leaks).

TEST(CppApi, MovesTransferOwnershipAndEmptyTheSource) {
    voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    VsrMesh *const handle = mesh.get();
    voussoir::Mesh moved(std::move(mesh));
    EXPECT_EQ(moved.get(), handle);
    EXPECT_EQ(mesh.get(), nullptr);  // NOLINT(bugprone-use-after-move): the state is specified
    EXPECT_FALSE(mesh);
    try {
        (void)mesh.counts();
        FAIL() << "no exception";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_NULL_POINTER);
        EXPECT_NE(e.message().find("`mesh`"), std::string::npos) << e.message();
    }
    // Assignment over a live handle frees the old one; self-move keeps the handle.
    voussoir::Mesh other(kPositions, kTriangles, kAnchored);
    other = std::move(moved);
    EXPECT_EQ(other.get(), handle);
    voussoir::Mesh &alias = other;
    other = std::move(alias);
    EXPECT_EQ(other.get(), handle);
    EXPECT_EQ(other.counts().vertices, 5u);

    voussoir::Settings settings;
    settings.max_iterations(20);
    voussoir::Settings settings2 = std::move(settings);
    EXPECT_FALSE(settings);
    EXPECT_THROW(settings.tolerance(1e-7), voussoir::Error);
    EXPECT_EQ(settings.try_tolerance(1e-7), VSR_STATUS_NULL_POINTER);

    voussoir::Result result = voussoir::form_find(other, settings2);
    voussoir::Result result2;
    result2 = std::move(result);
    EXPECT_FALSE(result);
    // A result owns its data: it outlives the mesh and settings it came from.
    other = voussoir::Mesh();
    settings2 = voussoir::Settings(nullptr);
    EXPECT_EQ(result2.counts().vertices, 5u);
    EXPECT_TRUE(result2.termination().converged()) << result2.termination_message();

    // release() hands the handle to the caller.
    VsrResult *raw = result2.release();
    EXPECT_FALSE(result2);
    vsr_result_destroy(raw);
}

TEST(CppApi, TryCreateLeavesTheOutputOnFailure) {
    voussoir::Mesh out(kPositions, kTriangles, kAnchored);
    VsrMesh *const before = out.get();
    EXPECT_EQ(
        voussoir::Mesh::try_create(kPositions.data(), 5, kTriangles.data(), 4, nullptr, 0, out),
        VSR_STATUS_NO_SUPPORT);
    EXPECT_EQ(out.get(), before);
    EXPECT_EQ(voussoir::Mesh::try_create(kPositions.data(), 5, kTriangles.data(), 4,
                                         kAnchored.data(), 4, out),
              VSR_STATUS_OK);
    EXPECT_NE(out.get(), before);
    EXPECT_STREQ(voussoir::last_error_message(), "");
}

// ---------------------------------------------------------------------------------------------
// Bit for bit against the C API.

struct CSolve {
    std::vector<double> positions, q, airy, weights, tau, external, loads, residuals, imbalance,
        holes, centres, segments, eps;
    std::vector<uint32_t> edges, segment_edges;
    VsrStressStatus status = VSR_STRESS_STATUS_SOLVED;
    double eps_inf = 0, objective = 0;
    std::size_t qp = 0;
};

template <typename T>
std::vector<T> c_copy(VsrStatus (*get)(const VsrResult *, T *, std::size_t, std::size_t *),
                      const VsrResult *r) {
    std::size_t n = 0;
    voussoir::check(get(r, nullptr, 0, &n));
    std::vector<T> out(n);
    voussoir::check(get(r, out.data(), n, &n));
    return out;
}

// The C API alone, with the same non-default settings as `cpp_settings` below.
CSolve c_solve(const vsrt::MeshData &m, bool form_find) {
    VsrMesh *mesh = nullptr;
    VsrSettings *settings = nullptr;
    VsrResult *r = nullptr;
    voussoir::check(vsr_mesh_create(m.positions.data(), m.n_vertices(), m.triangles.data(),
                                    m.n_faces(), m.anchored.data(), m.anchored.size(), &mesh));
    voussoir::check(vsr_settings_create(&settings));
    voussoir::check(vsr_settings_set_max_iterations(settings, 30));
    voussoir::check(vsr_settings_set_fairness(settings, 0.05));
    voussoir::check(vsr_settings_set_q_min(settings, 0.02, VSR_BOUND_KIND_RELATIVE));
    voussoir::check(vsr_settings_set_load_rule(settings, VSR_LOAD_RULE_VORONOI));
    voussoir::check(form_find ? vsr_form_find(mesh, settings, &r)
                              : vsr_analyse(mesh, settings, &r));
    CSolve s;
    s.positions = c_copy(vsr_result_positions, r);
    s.q = c_copy(vsr_result_force_densities, r);
    s.airy = c_copy(vsr_result_airy, r);
    s.weights = c_copy(vsr_result_weights, r);
    s.tau = c_copy(vsr_result_tau, r);
    s.external = c_copy(vsr_result_external_horizontal, r);
    s.loads = c_copy(vsr_result_loads, r);
    s.residuals = c_copy(vsr_result_residuals, r);
    s.imbalance = c_copy(vsr_result_horizontal_imbalance, r);
    s.holes = c_copy(vsr_result_hole_coefficients, r);
    s.centres = c_copy(vsr_result_force_diagram_centres, r);
    s.segments = c_copy(vsr_result_force_diagram_segments, r);
    s.edges = c_copy(vsr_result_edges, r);
    s.segment_edges = c_copy(vsr_result_force_diagram_segment_edges, r);
    if (form_find) s.eps = c_copy(vsr_result_eps_history, r);
    voussoir::check(vsr_result_stress_summary(r, &s.status, &s.eps_inf, &s.objective, &s.qp));
    vsr_result_destroy(r);
    vsr_settings_destroy(settings);
    vsr_mesh_destroy(mesh);
    return s;
}

voussoir::Settings cpp_settings() {
    voussoir::Settings s;
    s.max_iterations(30)
        .fairness(0.05)
        .q_min(0.02, VSR_BOUND_KIND_RELATIVE)
        .load_rule(VSR_LOAD_RULE_VORONOI);
    return s;
}

void expect_same(const CSolve &c, const voussoir::Result &r) {
    EXPECT_TRUE(same_bits(c.positions, r.positions()));
    EXPECT_TRUE(same_bits(c.q, r.force_densities()));
    EXPECT_TRUE(same_bits(c.airy, r.airy()));
    EXPECT_TRUE(same_bits(c.weights, r.weights()));
    EXPECT_TRUE(same_bits(c.tau, r.tau()));
    EXPECT_TRUE(same_bits(c.external, r.external_horizontal()));
    EXPECT_TRUE(same_bits(c.loads, r.loads()));
    EXPECT_TRUE(same_bits(c.residuals, r.residuals()));
    EXPECT_TRUE(same_bits(c.imbalance, r.horizontal_imbalance()));
    EXPECT_TRUE(same_bits(c.holes, r.hole_coefficients()));
    EXPECT_TRUE(same_bits(c.centres, r.force_diagram_centres()));
    EXPECT_TRUE(same_bits(c.segments, r.force_diagram_segments()));
    EXPECT_TRUE(same_bits(c.edges, r.edges()));
    EXPECT_TRUE(same_bits(c.segment_edges, r.force_diagram_segment_edges()));
    const voussoir::StressSummary s = r.stress_summary();
    EXPECT_EQ(s.status, c.status);
    EXPECT_TRUE(same_bits(std::vector<double>{c.eps_inf, c.objective},
                          std::vector<double>{s.eps_inf, s.objective}));
    EXPECT_EQ(s.qp_iterations, c.qp);
}

TEST(CppApi, AnalysisEqualsTheCApiBitForBit) {
    const vsrt::MeshData m = vsrt::generated("disk_off_centre_hole");
    const voussoir::Result r = voussoir::analyse(vsrt::make_mesh(m), cpp_settings());
    EXPECT_EQ(r.kind(), VSR_RESULT_KIND_ANALYSIS);
    expect_same(c_solve(m, false), r);
}

TEST(CppApi, FormFindingEqualsTheCApiBitForBit) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    const voussoir::Result r = voussoir::form_find(vsrt::make_mesh(m), cpp_settings());
    EXPECT_EQ(r.kind(), VSR_RESULT_KIND_FORM_FINDING);
    const CSolve c = c_solve(m, true);
    expect_same(c, r);
    EXPECT_TRUE(same_bits(c.eps, r.eps_history()));
    EXPECT_EQ(r.step_solvers().size(), r.termination().iterations);
    EXPECT_TRUE(r.stalled_vertices().empty());
    EXPECT_GE(r.height_change().max, r.height_change().rms);
    EXPECT_GE(r.distances().hausdorff, 0.0);
    EXPECT_GE(r.timings().total, 0.0);
    EXPECT_GT(r.regularisation(), 0.0);
    EXPECT_EQ(r.qp_solver(), VSR_QP_SOLVER_NATIVE);
    EXPECT_FALSE(r.termination_message().empty());
}

// A warm re-solve after raising one free vertex by 1% of the plan diagonal: converged, in
// equilibrium, supports where the edited mesh has them, in fewer stress steps than a cold form
// finding of the edited mesh; a previous result of another mesh is refused naming `previous`.
TEST(CppApi, AWarmResolveAfterAnEditTakesFewerSteps) {
    const vsrt::MeshData m = vsrt::generated("disk_cap");
    const voussoir::Settings settings;
    const voussoir::Result previous = voussoir::form_find(vsrt::make_mesh(m), settings);
    ASSERT_TRUE(previous.termination().converged());
    vsrt::MeshData edited = m;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (std::size_t v = 0; v < m.n_vertices(); ++v)
        for (int d = 0; d < 2; ++d) {
            lo[d] = std::min(lo[d], m.positions[3 * v + d]);
            hi[d] = std::max(hi[d], m.positions[3 * v + d]);
        }
    std::size_t free_vertex = 0;
    while (std::find(m.anchored.begin(), m.anchored.end(), free_vertex) != m.anchored.end())
        ++free_vertex;
    edited.positions[3 * free_vertex + 2] += 0.01 * std::hypot(hi[0] - lo[0], hi[1] - lo[1]);
    const voussoir::Mesh mesh = vsrt::make_mesh(edited);
    const voussoir::Result warm = voussoir::form_find_from(mesh, settings, previous);
    const voussoir::Result cold = voussoir::form_find(mesh, settings);
    ASSERT_TRUE(warm.termination().converged()) << warm.termination_message();
    ASSERT_TRUE(cold.termination().converged()) << cold.termination_message();
    EXPECT_LT(warm.termination().iterations, cold.termination().iterations);
    EXPECT_LT(warm.stress_summary().eps_inf, 1e-6);
    const std::vector<double> p = warm.positions();
    for (uint32_t a : edited.anchored) EXPECT_EQ(p[3 * a + 2], edited.positions[3 * a + 2]);

    voussoir::Result untouched;
    const voussoir::Mesh square(kPositions, kTriangles, kAnchored);
    EXPECT_EQ(voussoir::try_form_find_from(square, settings, previous, untouched),
              VSR_STATUS_INVALID_ARGUMENT);
    EXPECT_FALSE(untouched);
    try {
        (void)voussoir::form_find_from(square, settings, previous);
        ADD_FAILURE() << "another mesh was accepted";
    } catch (const voussoir::Error &e) {
        EXPECT_NE(std::string(e.what()).find("`previous`"), std::string::npos) << e.what();
    }
}

TEST(CppApi, AHangingMeshIsReadUpsideDown) {
    std::vector<double> hanging = kPositions;
    hanging[14] = -0.3;  // the apex below the supports' plane
    const voussoir::Result r = voussoir::form_find(voussoir::Mesh(hanging, kTriangles, kAnchored));
    EXPECT_TRUE(r.mirrored());
    EXPECT_GT(r.positions()[14], 0.0);
    EXPECT_FALSE(voussoir::form_find(voussoir::Mesh(kPositions, kTriangles, kAnchored)).mirrored());
    const voussoir::Result analysis = voussoir::analyse(voussoir::Mesh(hanging, kTriangles, kAnchored));
    EXPECT_THROW(analysis.mirrored(), voussoir::Error);
}

TEST(CppApi, GettersFillCallerStorage) {
    const voussoir::Result r = voussoir::analyse(voussoir::Mesh(kPositions, kTriangles, kAnchored));
    const std::vector<double> expected = r.positions();
    ASSERT_EQ(expected.size(), 15u);
    double buffer[20];
    EXPECT_EQ(r.positions(buffer, 20), 15u);
    EXPECT_TRUE(same_bits(expected, std::vector<double>(buffer, buffer + 15)));
    std::vector<double> reused;
    reused.reserve(64);
    const double *const storage = reused.data();
    r.positions(reused);
    EXPECT_EQ(reused.data(), storage) << "the caller's capacity was not reused";
    EXPECT_TRUE(same_bits(expected, reused));
    std::size_t needed = 0;
    EXPECT_EQ(r.try_positions(nullptr, 0, &needed), VSR_STATUS_OK);
    EXPECT_EQ(needed, 15u);
}

TEST(CppApi, MeshGettersAndSetters) {
    voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    const voussoir::Counts c = mesh.counts();
    EXPECT_EQ(c.vertices, 5u);
    EXPECT_EQ(c.edges, 8u);
    EXPECT_EQ(c.faces, 4u);
    EXPECT_EQ(c.holes, 0u);
    const std::vector<uint32_t> edges = mesh.edges();
    EXPECT_EQ(edges.size(), 16u);
    EXPECT_EQ(mesh.welded_ids(), (std::vector<uint32_t>{0, 1, 2, 3, 4}));
    EXPECT_TRUE(mesh.plan_flips().empty());
    EXPECT_TRUE(mesh.plan_nudges().empty());
    const std::vector<double> before = voussoir::analyse(mesh).loads();
    mesh.face_density({2, 2, 2, 2}).extra_loads({0, 0, 0, 0, 0.5}).prescribed_tau({0, 0, 0, 0, 0});
    mesh.horizontal_forces(std::vector<double>(10, 0.0));
    const std::vector<double> after = voussoir::analyse(mesh).loads();
    EXPECT_DOUBLE_EQ(after[4], 2 * before[4] + 0.5);
    // Polygon diagonals: marked as given (either order), read back smaller id first in edge
    // order, replaced by the next call.
    EXPECT_TRUE(mesh.polygon_diagonals().empty());
    mesh.set_polygon_diagonals({4, 2, 0, 4});
    EXPECT_EQ(mesh.polygon_diagonals(), (std::vector<uint32_t>{0, 4, 2, 4}));
    mesh.set_polygon_diagonals({3, 4});
    EXPECT_EQ(mesh.polygon_diagonals(), (std::vector<uint32_t>{3, 4}));
    mesh.set_polygon_diagonals({});
    EXPECT_TRUE(mesh.polygon_diagonals().empty());
}

TEST(CppApi, EverySettingReachesItsCSetter) {
    // Valid values through the builder; a wrong wiring would reject one or accept the bad
    // values of the hostile table above.
    voussoir::Settings s;
    s.tolerance(1e-7)
        .max_iterations(10)
        .stall_window(4)
        .q_min(0.0, VSR_BOUND_KIND_ABSOLUTE)
        .q_min_scope(VSR_EDGE_SCOPE_INTERIOR)
        .q_max(100.0, VSR_BOUND_KIND_ABSOLUTE)
        .tau_mode(VSR_TAU_MODE_ZERO)
        .hole_mode(VSR_HOLE_MODE_CONSTANT)
        .method(VSR_METHOD_PAPER)
        .fairness(0.1)
        .max_height_change(0.5)
        .load_rule(VSR_LOAD_RULE_PLAN_AREA)
        .formulation(VSR_FORMULATION_EDGE_BASED)
        .qp_solver(VSR_QP_SOLVER_CLARABEL)
        .regularisation(1e-9)
        .dual_length_bounds(0.0, INFINITY)
        .dual_length_smoothing(0.0, 0.5)
        .schedule_mu0(0.5)
        .schedule_beta(0.5)
        .schedule_mu_min(1e-8)
        .schedule_eta(1e-2)
        .schedule_pull(0.0)
        .proximal_weight(1e-5)
        .odt_iterations(0)
        .odt_free_boundary(true)
        .progress(nullptr);
    const voussoir::Result r =
        voussoir::analyse(voussoir::Mesh(kPositions, kTriangles, kAnchored), s);
    EXPECT_EQ(r.qp_solver(), VSR_QP_SOLVER_CLARABEL);
    EXPECT_DOUBLE_EQ(r.regularisation(), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Progress callbacks, files, threads.

TEST(CppApi, ProgressFunctionCancelsAndSeesEveryIteration) {
    const voussoir::Mesh mesh = vsrt::make_mesh(vsrt::generated("disk_cap"));
    std::vector<double> seen;
    voussoir::Settings settings;
    settings.progress([&seen](std::size_t iteration, double eps) {
        seen.push_back(eps);
        return iteration + 1 >= 2 ? voussoir::Progress::Cancel : voussoir::Progress::Continue;
    });
    // The function survives a move of the settings.
    const voussoir::Settings moved = std::move(settings);
    const voussoir::Result r = voussoir::form_find(mesh, moved);
    EXPECT_EQ(r.termination().reason, VSR_TERMINATION_CANCELLED);
    EXPECT_EQ(r.termination().iterations, 2u);
    EXPECT_EQ(seen, r.eps_history());
}

TEST(CppApi, ExceptionInProgressCancelsAndPropagates) {
    const voussoir::Mesh mesh = vsrt::make_mesh(vsrt::generated("disk_cap"));
    std::size_t calls = 0;
    voussoir::Settings settings;
    settings.progress([&calls](std::size_t, double) -> voussoir::Progress {
        ++calls;
        throw std::out_of_range("stop here");
    });
    EXPECT_THROW((void)voussoir::form_find(mesh, settings), std::out_of_range);
    EXPECT_EQ(calls, 1u);
    voussoir::Result r;
    EXPECT_EQ(voussoir::try_form_find(mesh, settings, r), VSR_STATUS_OK);
    EXPECT_EQ(r.termination().reason, VSR_TERMINATION_CANCELLED);
    // The next solve on this thread does not see the old exception.
    settings.progress(nullptr);
    EXPECT_TRUE(voussoir::form_find(mesh, settings).termination().converged());
}

TEST(CppApi, WriteAndReadBack) {
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    const voussoir::Result r = voussoir::form_find(mesh);
    const std::string path = std::string(VSR_OUTPUT_DIR) + "/cpp_api_square.off";
    r.write(mesh, path);
    voussoir::ReadOptions options;
    options.anchored = kAnchored;
    std::size_t merged = 99;
    const voussoir::Mesh back = voussoir::Mesh::read(path, options, &merged);
    EXPECT_EQ(merged, 0u);
    EXPECT_EQ(back.counts().vertices, 5u);
    EXPECT_TRUE(same_bits(voussoir::analyse(back).positions(), r.positions()));
    EXPECT_EQ(r.try_write(mesh, path + ".xyz"), VSR_STATUS_INVALID_ARGUMENT);
}

TEST(CppApi, ConcurrentSolvesOnSharedConstObjectsAgree) {
    const voussoir::Mesh mesh = vsrt::make_mesh(vsrt::generated("disk_cap"));
    std::atomic<int> calls{0};
    voussoir::Settings settings;
    settings.progress([&calls](std::size_t, double) {
        ++calls;
        return voussoir::Progress::Continue;
    });
    std::vector<double> z[2];
    std::thread threads[2];
    for (int k = 0; k < 2; ++k)
        threads[k] =
            std::thread([&, k] { z[k] = voussoir::form_find(mesh, settings).positions(); });
    for (auto &t : threads) t.join();
    const voussoir::Result alone = voussoir::form_find(mesh, settings);
    EXPECT_TRUE(same_bits(z[0], z[1]));
    EXPECT_TRUE(same_bits(z[0], alone.positions()));
    EXPECT_EQ(calls.load(), 3 * static_cast<int>(alone.termination().iterations));
}

// ---------------------------------------------------------------------------------------------
// Masonry assessment.

// The C API's assessment of `mesh` (0.1 thick) with `objective`, for comparison.
struct CAssessment {
    std::vector<double> positions, q, loads, residuals, lower, upper, reactions, joints;
    std::vector<uint32_t> joint_vertices;
    double worst_joint = -1;
    uint32_t worst_joint_vertex = 0;
    uint32_t feasible = 0;
    VsrTermination termination = VSR_TERMINATION_NUMERICAL_ERROR;
    std::size_t iterations = 0;
    double figures[4] = {0, 0, 0, 0};
};

std::vector<double> c_doubles(
    VsrStatus (*get)(const VsrAssessment *, double *, std::size_t, std::size_t *),
    const VsrAssessment *a) {
    std::size_t n = 0;
    EXPECT_EQ(get(a, nullptr, 0, &n), VSR_STATUS_OK);
    std::vector<double> v(n);
    EXPECT_EQ(get(a, v.data(), n, &n), VSR_STATUS_OK);
    return v;
}

// With `joints` (springing, reach per vertex), the envelope's springing joints set first.
CAssessment c_assess(
    const voussoir::Mesh &mesh, VsrObjective objective,
    const std::pair<std::vector<double>, std::vector<double>> *joints = nullptr) {
    const double t = 0.1;
    VsrEnvelope *e = nullptr;
    VsrAssessSettings *s = nullptr;
    VsrAssessment *a = nullptr;
    EXPECT_EQ(vsr_envelope_from_thickness(mesh.get(), &t, 1, &e), VSR_STATUS_OK);
    if (joints) {
        EXPECT_EQ(vsr_envelope_set_springing(e, joints->first.data(), joints->first.size(),
                                             joints->second.data(), joints->second.size()),
                  VSR_STATUS_OK);
    }
    EXPECT_EQ(vsr_assess_settings_create(&s), VSR_STATUS_OK);
    EXPECT_EQ(vsr_assess_settings_set_objective(s, objective), VSR_STATUS_OK);
    EXPECT_EQ(vsr_assess(mesh.get(), e, s, &a), VSR_STATUS_OK);
    CAssessment c;
    c.positions = c_doubles(vsr_assessment_positions, a);
    c.q = c_doubles(vsr_assessment_force_densities, a);
    c.loads = c_doubles(vsr_assessment_loads, a);
    c.residuals = c_doubles(vsr_assessment_residuals, a);
    c.lower = c_doubles(vsr_assessment_lower, a);
    c.upper = c_doubles(vsr_assessment_upper, a);
    c.reactions = c_doubles(vsr_assessment_reactions, a);
    c.joints = c_doubles(vsr_assessment_joints, a);
    std::size_t n_joints = 0;
    EXPECT_EQ(vsr_assessment_joint_vertices(a, nullptr, 0, &n_joints), VSR_STATUS_OK);
    c.joint_vertices.resize(n_joints);
    EXPECT_EQ(vsr_assessment_joint_vertices(a, c.joint_vertices.data(), n_joints, &n_joints),
              VSR_STATUS_OK);
    EXPECT_EQ(vsr_assessment_worst_joint(a, &c.worst_joint, &c.worst_joint_vertex),
              VSR_STATUS_OK);
    double seconds = 0;
    EXPECT_EQ(vsr_assessment_outcome(a, &c.feasible, &c.termination, &c.iterations, &seconds),
              VSR_STATUS_OK);
    EXPECT_EQ(vsr_assessment_figures(a, &c.figures[0], &c.figures[1], &c.figures[2],
                                     &c.figures[3]),
              VSR_STATUS_OK);
    vsr_assessment_destroy(a);
    vsr_assess_settings_destroy(s);
    vsr_envelope_destroy(e);
    return c;
}

TEST(CppApi, AssessmentEqualsTheCApiBitForBit) {
    // A small mesh: the comparison is of layers, not of the search.
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    for (VsrObjective objective : {VSR_OBJECTIVE_FIT, VSR_OBJECTIVE_MIN_THICKNESS}) {
        voussoir::AssessSettings settings;
        settings.objective(objective);
        const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 0.1);
        const voussoir::Assessment a = voussoir::assess(mesh, envelope, settings);
        const CAssessment c = c_assess(mesh, objective);
        EXPECT_EQ(a.objective(), objective);
        EXPECT_TRUE(same_bits(c.positions, a.positions()));
        EXPECT_TRUE(same_bits(c.q, a.force_densities()));
        EXPECT_TRUE(same_bits(c.loads, a.loads()));
        EXPECT_TRUE(same_bits(c.residuals, a.residuals()));
        EXPECT_TRUE(same_bits(c.lower, a.lower()));
        EXPECT_TRUE(same_bits(c.upper, a.upper()));
        EXPECT_TRUE(same_bits(c.reactions, a.reactions()));
        EXPECT_TRUE(same_bits(c.joints, a.joints()));
        EXPECT_EQ(c.joint_vertices, a.joint_vertices());
        EXPECT_EQ(a.joints().size(), 9 * a.joint_vertices().size());
        const voussoir::WorstJoint worst = a.worst_joint();
        EXPECT_TRUE(same_bits(std::vector<double>{c.worst_joint}, std::vector<double>{worst.excess}));
        EXPECT_EQ(c.worst_joint_vertex, worst.vertex);
        const std::vector<double> joints = a.joints();
        for (std::size_t j = 0; j + 9 <= joints.size(); j += 9) {
            // A certified surface's reaction line meets its springing plane within the reach.
            EXPECT_LE(joints[j + 8], joints[j + 1] * (1 + 1e-6) + 1e-9) << "joint " << j / 9;
        }
        EXPECT_EQ(a.edges(), mesh.edges());
        const voussoir::AssessmentOutcome o = a.outcome();
        EXPECT_TRUE(o.feasible);
        EXPECT_EQ(o.feasible, c.feasible == 1u);
        EXPECT_EQ(o.termination, c.termination);
        EXPECT_EQ(o.iterations, c.iterations);
        const voussoir::AssessmentFigures f = a.figures();
        EXPECT_TRUE(same_bits(std::vector<double>(c.figures, c.figures + 4),
                              std::vector<double>{f.thickness_scale, f.safety_factor,
                                                  f.thrust_horizontal, f.load_factor}));
        const voussoir::Certificate cert = a.certificate();
        EXPECT_LT(cert.eps_inf, 1e-6);
        EXPECT_LE(cert.worst_bound, 1e-9);  // inside its bounds to the certificate's slack
        EXPECT_FALSE(a.termination_message().empty());
        // The bounds the surface lies within, at the reported thickness.
        const std::vector<double> z = a.positions(), lo = a.lower(), hi = a.upper();
        for (std::size_t v = 0; v < lo.size(); ++v) {
            EXPECT_GE(z[3 * v + 2], lo[v] - 1e-9);
            EXPECT_LE(z[3 * v + 2], hi[v] + 1e-9);
        }
        if (objective == VSR_OBJECTIVE_MIN_THICKNESS) {
            EXPECT_LT(f.thickness_scale, 1.0);
            EXPECT_DOUBLE_EQ(f.safety_factor, 1.0 / f.thickness_scale);
        }
    }
}

// The pyramid 0.3 high in a slab 0.8 thick holds the plane through its supports: ever
// flatter surfaces carry its weight, and the greatest thrust has no bound; 0.1 thick it has.
// The factor on a load at its apex has none.
TEST(CppApi, AnUnboundedObjectiveSaysSo) {
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    voussoir::AssessSettings settings;
    settings.objective(VSR_OBJECTIVE_MAX_THRUST);
    for (double t : {0.8, 0.1}) {
        const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, t);
        const voussoir::Assessment a = voussoir::assess(mesh, envelope, settings);
        EXPECT_TRUE(a.outcome().converged()) << t;
        EXPECT_EQ(a.unbounded(), t > 0.5) << t;
    }
    // A load on the apex alone is carried by the pyramid itself, at any factor.
    settings.objective(VSR_OBJECTIVE_MAX_LOAD).load_pattern({0, 0, 0, 0, 1});
    const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 0.1);
    const voussoir::Assessment a = voussoir::assess(mesh, envelope, settings);
    EXPECT_TRUE(a.outcome().converged());
    EXPECT_TRUE(a.unbounded());
    EXPECT_GT(a.figures().load_factor, 0.0);
}

TEST(CppApi, AFreeCornerHoldsNoThrustSurface) {
    // Anchored at three corners, the fourth (vertex 3) is free with every edge leaving it on
    // one side in plan: compression cannot balance it, so no envelope holds a surface.
    const voussoir::Mesh mesh(kPositions, kTriangles, {0, 1, 2});
    const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 1.0);
    const voussoir::Assessment a = voussoir::assess(mesh, envelope, voussoir::AssessSettings());
    const voussoir::AssessmentOutcome outcome = a.outcome();
    EXPECT_FALSE(outcome.feasible);
    EXPECT_EQ(outcome.termination, VSR_TERMINATION_INFEASIBLE);
    EXPECT_EQ(outcome.iterations, 0u);
    const std::string message = a.termination_message();
    EXPECT_NE(message.find("vertex 3 is a free corner"), std::string::npos) << message;
    // The centre keeps the diagonal from 0 to 2, an arch between supports: only 3 is stranded.
    EXPECT_EQ(a.stranded(), std::vector<std::uint32_t>{3});
}

TEST(CppApi, SpringingJointsReachTheCSetter) {
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 0.1);
    const std::vector<double> springing = envelope.springing(), reach = envelope.reach();
    ASSERT_EQ(springing.size(), 5u);
    ASSERT_EQ(reach.size(), 5u);
    // Bad joints throw the C status with its message naming the argument; nothing changes.
    auto failure = [&](const std::vector<double> &s, const std::vector<double> &r) {
        try {
            envelope.set_springing(s, r);
        } catch (const voussoir::Error &e) {
            EXPECT_EQ(e.status(), VSR_STATUS_INVALID_ARGUMENT);
            return e.message();
        }
        return std::string("no error");
    };
    EXPECT_NE(failure({0, 0}, reach).find("`springing`"), std::string::npos);
    std::vector<double> negative = reach;
    negative[2] = -0.5;
    const std::string message = failure(springing, negative);
    EXPECT_NE(message.find("`reach`"), std::string::npos) << message;
    EXPECT_NE(message.find("vertex 2"), std::string::npos) << message;
    EXPECT_TRUE(same_bits(envelope.reach(), reach));
    // A narrow joint and no joint: the greatest thrust equals the C API's, bit for bit.
    std::vector<double> narrow = reach, none(reach.size(), std::numeric_limits<double>::infinity());
    for (double &b : narrow) b *= 0.2;
    voussoir::AssessSettings settings;
    settings.objective(VSR_OBJECTIVE_MAX_THRUST);
    std::vector<double> thrusts;
    for (const std::vector<double> &r : {narrow, none}) {
        EXPECT_EQ(&envelope.set_springing(springing, r), &envelope);
        EXPECT_TRUE(same_bits(envelope.reach(), r));
        EXPECT_TRUE(same_bits(envelope.springing(), springing));
        const voussoir::Assessment a = voussoir::assess(mesh, envelope, settings);
        const std::pair<std::vector<double>, std::vector<double>> joints{springing, r};
        const CAssessment c = c_assess(mesh, VSR_OBJECTIVE_MAX_THRUST, &joints);
        EXPECT_TRUE(same_bits(c.positions, a.positions()));
        EXPECT_TRUE(same_bits(c.joints, a.joints()));
        EXPECT_TRUE(a.outcome().feasible);
        thrusts.push_back(a.figures().thrust_horizontal);
    }
    // The joint binds: without it the reaction leans further.
    EXPECT_LT(thrusts[0], thrusts[1] * (1 - 1e-3));
}

TEST(CppApi, AssessmentInputErrorsThrowTheCStatus) {
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    auto status_of = [](const std::function<void()> &call) {
        try {
            call();
        } catch (const voussoir::Error &e) {
            EXPECT_EQ(e.message(), voussoir::last_error_message());
            return e.status();
        }
        return VSR_STATUS_OK;
    };
    EXPECT_EQ(status_of([&] { (void)voussoir::Envelope::from_thickness(mesh, 0.0); }),
              VSR_STATUS_INVALID_ARGUMENT);
    EXPECT_EQ(status_of([&] { (void)voussoir::Envelope::from_thickness(mesh, kNaN); }),
              VSR_STATUS_NON_FINITE);
    EXPECT_EQ(status_of([&] {
                  (void)voussoir::Envelope::from_thickness(mesh, std::vector<double>{0.1, 0.1});
              }),
              VSR_STATUS_INVALID_ARGUMENT);
    try {
        (void)voussoir::Envelope::from_surfaces(mesh, {0, 0, 0, 1}, kTriangles, kPositions,
                                                kTriangles);
        ADD_FAILURE() << "a ragged intrados was accepted";
    } catch (const voussoir::Error &e) {
        // Checked by the C++ layer before the C call: no last error of the C library.
        EXPECT_EQ(e.status(), VSR_STATUS_INVALID_ARGUMENT);
        EXPECT_NE(e.message().find("`intrados`"), std::string::npos);
    }
    voussoir::AssessSettings settings;
    EXPECT_EQ(status_of([&] { settings.objective(static_cast<VsrObjective>(99)); }),
              VSR_STATUS_INVALID_ENUM);
    EXPECT_EQ(settings.try_unit_weight(-1.0), VSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(voussoir::last_error_message()).find("unit_weight"), std::string::npos);
    EXPECT_EQ(settings.try_tolerance(kNaN), VSR_STATUS_NON_FINITE);
    const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 0.1);
    settings.objective(VSR_OBJECTIVE_MAX_LOAD);
    EXPECT_EQ(status_of([&] { (void)voussoir::assess(mesh, envelope, settings); }),
              VSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(voussoir::last_error_message()).find("load_pattern"),
              std::string::npos);
    voussoir::Assessment out;
    EXPECT_EQ(voussoir::try_assess(mesh, voussoir::Envelope(), settings, out),
              VSR_STATUS_NULL_POINTER);
    EXPECT_FALSE(out);
    // The pattern reaches vsr_assess (its length is checked there).
    settings.load_pattern({0, 0, 0, 1});
    EXPECT_EQ(status_of([&] { (void)voussoir::assess(mesh, envelope, settings); }),
              VSR_STATUS_INVALID_ARGUMENT);
    EXPECT_NE(std::string(voussoir::last_error_message()).find("has 4 entries"),
              std::string::npos);
    // A free support stands on or above its springing plane, the support's height (method.md
    // §16.1): the least thrust keeps it there, the greatest raises it within the joint; fixed
    // ones stay, also in moved settings.
    settings.objective(VSR_OBJECTIVE_MIN_THRUST).q_min(0.0, VSR_BOUND_KIND_ABSOLUTE);
    const double least_z = voussoir::assess(mesh, envelope, settings).positions()[2];
    settings.objective(VSR_OBJECTIVE_MAX_THRUST);
    const double greatest_z = voussoir::assess(mesh, envelope, settings).positions()[2];
    settings.objective(VSR_OBJECTIVE_MIN_THRUST).fixed_supports(true);
    const voussoir::AssessSettings moved = std::move(settings);
    const voussoir::Assessment a = voussoir::assess(mesh, envelope, moved);
    EXPECT_TRUE(a.outcome().converged());
    EXPECT_EQ(a.positions()[2], 0.0);
    EXPECT_GE(least_z, -1e-9);
    EXPECT_GT(greatest_z, least_z + 1e-3);
}

TEST(CppApi, AssessmentProgressCancelsAndExceptionsPropagate) {
    const voussoir::Mesh mesh = vsrt::make_mesh(vsrt::generated("disk_cap"));
    const voussoir::Envelope envelope = voussoir::Envelope::from_thickness(mesh, 0.1);
    std::vector<std::size_t> steps;
    voussoir::AssessSettings settings;
    settings.objective(VSR_OBJECTIVE_MIN_THRUST).progress([&steps](std::size_t step, double) {
        steps.push_back(step);
        return steps.size() >= 2 ? voussoir::Progress::Cancel : voussoir::Progress::Continue;
    });
    const voussoir::Assessment a = voussoir::assess(mesh, envelope, settings);
    EXPECT_EQ(a.outcome().termination, VSR_TERMINATION_CANCELLED);
    EXPECT_EQ(steps, (std::vector<std::size_t>{1, 2}));
    settings.progress([](std::size_t, double) -> voussoir::Progress {
        throw std::out_of_range("stop the assessment");
    });
    EXPECT_THROW((void)voussoir::assess(mesh, envelope, settings), std::out_of_range);
    voussoir::Assessment r;
    EXPECT_EQ(voussoir::try_assess(mesh, envelope, settings, r), VSR_STATUS_OK);
    EXPECT_EQ(r.outcome().termination, VSR_TERMINATION_CANCELLED);
}

TEST(CppApi, MinThicknessOfAFamilyFitsItsEnvelopeAndRethrows) {
    const voussoir::Mesh mesh(kPositions, kTriangles, kAnchored);
    // Shells of radii R (1 -+ t/2) about the plan's centre read vertically, R the corners'
    // distance, the springing plane below the intrados.
    const double cx = 0.5, cy = 0.5, radius = std::sqrt(0.5);
    std::size_t calls = 0;
    const voussoir::FamilyBoundsFn shells = [&](double t, std::vector<double> &lower,
                                                std::vector<double> &upper) {
        ++calls;
        for (std::size_t v = 0; v < lower.size(); ++v) {
            const double r = std::hypot(kPositions[3 * v] - cx, kPositions[3 * v + 1] - cy);
            auto at = [r, radius](double sphere) {
                return std::sqrt(std::max(sphere * sphere * radius * radius - r * r, 0.0));
            };
            lower[v] = at(1 - 0.5 * t);
            upper[v] = at(1 + 0.5 * t);
        }
    };
    const voussoir::FamilyThickness f = voussoir::min_thickness_of_family(mesh, shells, 0.1);
    EXPECT_GT(calls, 0u);
    EXPECT_TRUE(std::isfinite(f.thickness) && f.thickness >= 0.0 && f.thickness <= 0.1);
    EXPECT_TRUE(f.assessment.outcome().feasible);
    EXPECT_EQ(f.assessment.objective(), VSR_OBJECTIVE_MIN_THICKNESS);
    EXPECT_LT(f.assessment.certificate().eps_inf, 1e-6);
    const std::vector<double> z = f.assessment.positions(), lo = f.assessment.lower(),
                              hi = f.assessment.upper();
    for (std::size_t v = 0; v < lo.size(); ++v) {
        EXPECT_GE(z[3 * v + 2], lo[v] - 1e-9);
        EXPECT_LE(z[3 * v + 2], hi[v] + 1e-9);
    }
    const voussoir::FamilyBoundsFn throwing = [](double, std::vector<double> &,
                                                 std::vector<double> &) {
        throw std::out_of_range("no such shell");
    };
    EXPECT_THROW((void)voussoir::min_thickness_of_family(mesh, throwing, 0.1), std::out_of_range);
    const voussoir::FamilyBoundsFn resizing = [](double, std::vector<double> &lower,
                                                 std::vector<double> &) { lower.pop_back(); };
    try {
        (void)voussoir::min_thickness_of_family(mesh, resizing, 0.1);
        ADD_FAILURE() << "a resized vector was accepted";
    } catch (const voussoir::Error &e) {
        EXPECT_EQ(e.status(), VSR_STATUS_INVALID_ARGUMENT);
    }
}

TEST(CppApi, Versions) {
    EXPECT_STREQ(voussoir::version(), VSR_VERSION_STRING);
    EXPECT_EQ(voussoir::abi_version(), uint32_t{VSR_ABI_VERSION});
    EXPECT_TRUE(voussoir::abi_compatible());
    EXPECT_STREQ(voussoir::status_name(VSR_STATUS_NO_SUPPORT), "VSR_STATUS_NO_SUPPORT");
}

}  // namespace
