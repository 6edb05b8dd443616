// Contract tests of the C ABI through the installed header, from C++: the hostile-input table
// of the C ABI (NULL in each slot, zero / huge / overflowing lengths, out-of-range ids, NaN,
// invalid enums, NaN / negative / out-of-range settings, destroy(NULL), short buffers), each
// with the right status, a non-empty one-line message naming the argument, and untouched
// outputs and handles; then concurrent solves on shared const handles. Handles are owned by
// voussoir.hpp's classes (test_cpp_api.cpp tests those).
#include "support.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

namespace {

using vsrt::MeshData;

// A square of 4 triangles around a raised centre vertex, corners anchored (as tests/c/hostile.c).
const std::vector<double> kPositions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3};
const std::vector<uint32_t> kTriangles = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
const std::vector<uint32_t> kAnchored = {0, 1, 2, 3};
constexpr std::size_t kV = 5, kF = 4;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kMax = std::numeric_limits<std::size_t>::max();

VsrMesh *const kSentinelMesh = reinterpret_cast<VsrMesh *>(uintptr_t{0xdeadbee8u});
VsrSettings *const kSentinelSettings = reinterpret_cast<VsrSettings *>(uintptr_t{0xdeadbee8u});
VsrResult *const kSentinelResult = reinterpret_cast<VsrResult *>(uintptr_t{0xdeadbee8u});

// The status, and a message that is non-empty, one line, and names `argument` in backquotes.
::testing::AssertionResult Fails(VsrStatus got, VsrStatus want, const std::string &argument) {
    const std::string message = vsr_last_error_message();
    if (got != want)
        return ::testing::AssertionFailure() << "got " << vsr_status_name(got) << ", want "
                                             << vsr_status_name(want) << " (" << message << ")";
    if (message.empty()) return ::testing::AssertionFailure() << "empty message";
    if (message.find('\n') != std::string::npos)
        return ::testing::AssertionFailure() << "message on several lines: " << message;
    if (message.find("`" + argument + "`") == std::string::npos)
        return ::testing::AssertionFailure() << "message does not name `" << argument
                                             << "`: " << message;
    return ::testing::AssertionSuccess() << vsr_status_name(got) << ": " << message;
}

::testing::AssertionResult Succeeds(VsrStatus got) {
    if (got != VSR_STATUS_OK)
        return ::testing::AssertionFailure()
               << vsr_status_name(got) << ": " << vsr_last_error_message();
    if (vsr_last_error_message()[0] != '\0')
        return ::testing::AssertionFailure() << "success left a message";
    return ::testing::AssertionSuccess();
}

voussoir::Mesh square() {
    return vsrt::make_mesh({"square", kPositions, kTriangles, kAnchored});
}

// Force densities of an analysis with these handles (to show a handle kept its state).
std::vector<double> analyse_q(const VsrMesh *mesh, const VsrSettings *settings) {
    VsrResult *raw = nullptr;
    voussoir::check(vsr_analyse(mesh, settings, &raw));
    return voussoir::Result(raw).force_densities();
}

// ---------------------------------------------------------------------------------------------
// vsr_mesh_create

struct MeshCase {
    const char *name;
    std::function<VsrStatus(VsrMesh **)> call;
    VsrStatus want;
    const char *argument;
};

std::vector<MeshCase> mesh_cases() {
    static std::vector<double> nan_z = [] {
        auto p = kPositions;
        p[13] = kNaN;   // y of the centre
        return p;
    }();
    static std::vector<double> inf_x = [] {
        auto p = kPositions;
        p[3] = kInf;
        return p;
    }();
    static std::vector<uint32_t> bad_index = [] {
        auto t = kTriangles;
        t[5] = 5;
        return t;
    }();
    static std::vector<uint32_t> repeated_vertex = [] {
        auto t = kTriangles;
        t[2] = t[1];
        return t;
    }();
    static std::vector<double> flat = [] {
        auto p = kPositions;
        p[12] = 0.5, p[13] = 0.0;   // centre on the edge 0-1: face 0 has zero plan area
        return p;
    }();
    // The square twice, the copy shifted by half a side and raised: stacked in plan.
    static std::vector<double> stacked = [] {
        auto p = kPositions;
        for (std::size_t i = 0; i < kPositions.size(); ++i)
            p.push_back(kPositions[i] + (i % 3 == 2 ? 1.0 : 0.5));
        return p;
    }();
    static std::vector<uint32_t> stacked_triangles = [] {
        auto t = kTriangles;
        for (uint32_t v : kTriangles) t.push_back(v + 5);
        return t;
    }();
    static const std::vector<uint32_t> stacked_anchors = {0, 1, 2, 3, 5, 6, 7, 8};
    static std::vector<double> huge = [] {
        auto p = kPositions;
        for (double &c : p) c *= 1e200;
        return p;
    }();
    static const std::vector<uint32_t> bad_anchors = {0, 1, 2, 99};
    static const std::vector<uint32_t> twice = {0, 1, 2, 2};
    const double *p = kPositions.data();
    const uint32_t *t = kTriangles.data();
    const uint32_t *a = kAnchored.data();
    return {
        {"null_positions", [=](VsrMesh **o) { return vsr_mesh_create(nullptr, kV, t, kF, a, 4, o); },
         VSR_STATUS_NULL_POINTER, "positions"},
        {"null_triangles", [=](VsrMesh **o) { return vsr_mesh_create(p, kV, nullptr, kF, a, 4, o); },
         VSR_STATUS_NULL_POINTER, "triangles"},
        {"null_anchored", [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kF, nullptr, 4, o); },
         VSR_STATUS_NULL_POINTER, "anchored"},
        {"null_out", [=](VsrMesh **) { return vsr_mesh_create(p, kV, t, kF, a, 4, nullptr); },
         VSR_STATUS_NULL_POINTER, "out"},
        {"zero_vertices", [=](VsrMesh **o) { return vsr_mesh_create(p, 0, t, kF, a, 4, o); },
         VSR_STATUS_EMPTY_MESH, "positions"},
        {"huge_vertices", [=](VsrMesh **o) { return vsr_mesh_create(p, kMax, t, kF, a, 4, o); },
         VSR_STATUS_LENGTH_OVERFLOW, "positions"},
        {"vertices_times_3_overflows",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kMax / 3 + 1, t, kF, a, 4, o); },
         VSR_STATUS_LENGTH_OVERFLOW, "positions"},
        {"more_than_u32_vertices",
         [=](VsrMesh **o) {
             return vsr_mesh_create(p, std::size_t{UINT32_MAX} + 1, t, kF, a, 4, o);
         },
         VSR_STATUS_LENGTH_OVERFLOW, "positions"},
        {"triangles_times_3_overflows",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kMax / 2, a, 4, o); },
         VSR_STATUS_LENGTH_OVERFLOW, "triangles"},
        {"anchored_huge", [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kF, a, kMax, o); },
         VSR_STATUS_LENGTH_OVERFLOW, "anchored"},
        {"triangle_index_out_of_range",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kV, bad_index.data(), kF, a, 4, o); },
         VSR_STATUS_INDEX_OUT_OF_RANGE, "triangles"},
        {"anchor_out_of_range",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kF, bad_anchors.data(), 4, o); },
         VSR_STATUS_INDEX_OUT_OF_RANGE, "anchored"},
        {"anchor_twice",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kF, twice.data(), 4, o); },
         VSR_STATUS_INVALID_ARGUMENT, "anchored"},
        {"nan_coordinate",
         [=](VsrMesh **o) { return vsr_mesh_create(nan_z.data(), kV, t, kF, a, 4, o); },
         VSR_STATUS_NON_FINITE, "positions"},
        {"infinite_coordinate",
         [=](VsrMesh **o) { return vsr_mesh_create(inf_x.data(), kV, t, kF, a, 4, o); },
         VSR_STATUS_NON_FINITE, "positions"},
        {"repeated_vertex_in_face",
         [=](VsrMesh **o) { return vsr_mesh_create(p, kV, repeated_vertex.data(), kF, a, 4, o); },
         VSR_STATUS_INVALID_TOPOLOGY, "triangles"},
        {"zero_area_face",
         [=](VsrMesh **o) { return vsr_mesh_create(flat.data(), kV, t, kF, a, 4, o); },
         VSR_STATUS_INVALID_PLAN, "positions"},
        {"no_support", [=](VsrMesh **o) { return vsr_mesh_create(p, kV, t, kF, a, 0, o); },
         VSR_STATUS_NO_SUPPORT, "anchored"},
        {"stacked_in_plan",
         [=](VsrMesh **o) {
             return vsr_mesh_create(stacked.data(), 2 * kV, stacked_triangles.data(), 2 * kF,
                                    stacked_anchors.data(), 8, o);
         },
         VSR_STATUS_INVALID_PLAN, "positions"},
        {"coordinates_of_1e200",
         [=](VsrMesh **o) { return vsr_mesh_create(huge.data(), kV, t, kF, a, 4, o); },
         VSR_STATUS_INVALID_ARGUMENT, "positions"},
    };
}

void PrintTo(const MeshCase &c, std::ostream *os) { *os << c.name; }

class MeshCreate : public ::testing::TestWithParam<MeshCase> {};

TEST_P(MeshCreate, FailsCleanly) {
    const MeshCase &c = GetParam();
    VsrMesh *out = kSentinelMesh;
    EXPECT_TRUE(Fails(c.call(&out), c.want, c.argument));
    EXPECT_EQ(out, kSentinelMesh) << "output written on failure";
    // The failure leaves nothing behind: the same thread can go on.
    voussoir::Mesh ok = square();
    EXPECT_STREQ(vsr_last_error_message(), "");
}

INSTANTIATE_TEST_SUITE_P(Contract, MeshCreate, ::testing::ValuesIn(mesh_cases()),
                         [](const auto &info) { return std::string(info.param.name); });

// ---------------------------------------------------------------------------------------------
// Settings setters: status, message, and the settings keep their previous state.

struct SetterCase {
    const char *name;
    std::function<VsrStatus(VsrSettings *)> call;
    VsrStatus want;
    const char *argument;
};

std::vector<SetterCase> setter_cases() {
    return {
        {"tolerance_null", [](VsrSettings *) { return vsr_settings_set_tolerance(nullptr, 1e-6); },
         VSR_STATUS_NULL_POINTER, "settings"},
        {"tolerance_nan", [](VsrSettings *s) { return vsr_settings_set_tolerance(s, kNaN); },
         VSR_STATUS_NON_FINITE, "tolerance"},
        {"tolerance_inf", [](VsrSettings *s) { return vsr_settings_set_tolerance(s, kInf); },
         VSR_STATUS_NON_FINITE, "tolerance"},
        {"tolerance_negative", [](VsrSettings *s) { return vsr_settings_set_tolerance(s, -1.0); },
         VSR_STATUS_INVALID_ARGUMENT, "tolerance"},
        {"tolerance_zero", [](VsrSettings *s) { return vsr_settings_set_tolerance(s, 0.0); },
         VSR_STATUS_INVALID_ARGUMENT, "tolerance"},
        {"max_iterations_zero", [](VsrSettings *s) { return vsr_settings_set_max_iterations(s, 0); },
         VSR_STATUS_INVALID_ARGUMENT, "max_iterations"},
        {"stall_window_zero", [](VsrSettings *s) { return vsr_settings_set_stall_window(s, 0); },
         VSR_STATUS_INVALID_ARGUMENT, "iterations"},
        {"q_min_negative",
         [](VsrSettings *s) { return vsr_settings_set_q_min(s, -0.5, VSR_BOUND_KIND_ABSOLUTE); },
         VSR_STATUS_INVALID_ARGUMENT, "value"},
        {"q_min_nan",
         [](VsrSettings *s) { return vsr_settings_set_q_min(s, kNaN, VSR_BOUND_KIND_RELATIVE); },
         VSR_STATUS_NON_FINITE, "value"},
        {"q_min_bad_kind", [](VsrSettings *s) { return vsr_settings_set_q_min(s, 0.1, 7); },
         VSR_STATUS_INVALID_ENUM, "kind"},
        {"q_min_scope_bad", [](VsrSettings *s) { return vsr_settings_set_q_min_scope(s, 42); },
         VSR_STATUS_INVALID_ENUM, "scope"},
        {"q_max_nan",
         [](VsrSettings *s) { return vsr_settings_set_q_max(s, kNaN, VSR_BOUND_KIND_RELATIVE); },
         VSR_STATUS_NON_FINITE, "value"},
        {"q_max_zero",
         [](VsrSettings *s) { return vsr_settings_set_q_max(s, 0.0, VSR_BOUND_KIND_RELATIVE); },
         VSR_STATUS_INVALID_ARGUMENT, "value"},
        // Default q_min is 0.05 relative. The message names the option (`q_max`), not the C
        // parameter (`value`) as the other q_min / q_max messages do.
        {"q_max_below_q_min",
         [](VsrSettings *s) { return vsr_settings_set_q_max(s, 0.01, VSR_BOUND_KIND_RELATIVE); },
         VSR_STATUS_INVALID_ARGUMENT, "q_max"},
        {"q_max_bad_kind", [](VsrSettings *s) { return vsr_settings_set_q_max(s, 1.0, 99); },
         VSR_STATUS_INVALID_ENUM, "kind"},
        {"tau_mode_bad", [](VsrSettings *s) { return vsr_settings_set_tau_mode(s, 42); },
         VSR_STATUS_INVALID_ENUM, "mode"},
        {"hole_mode_bad", [](VsrSettings *s) { return vsr_settings_set_hole_mode(s, 42); },
         VSR_STATUS_INVALID_ENUM, "mode"},
        {"load_rule_bad", [](VsrSettings *s) { return vsr_settings_set_load_rule(s, 42); },
         VSR_STATUS_INVALID_ENUM, "rule"},
        {"formulation_bad", [](VsrSettings *s) { return vsr_settings_set_formulation(s, 42); },
         VSR_STATUS_INVALID_ENUM, "formulation"},
        {"regularisation_negative",
         [](VsrSettings *s) { return vsr_settings_set_regularisation(s, -1e-10); },
         VSR_STATUS_INVALID_ARGUMENT, "epsilon"},
        {"regularisation_nan", [](VsrSettings *s) { return vsr_settings_set_regularisation(s, kNaN); },
         VSR_STATUS_NON_FINITE, "epsilon"},
        {"mu0_negative", [](VsrSettings *s) { return vsr_settings_set_schedule_mu0(s, -1.0); },
         VSR_STATUS_INVALID_ARGUMENT, "mu0"},
        {"beta_above_one", [](VsrSettings *s) { return vsr_settings_set_schedule_beta(s, 2.0); },
         VSR_STATUS_INVALID_ARGUMENT, "beta"},
        {"beta_negative", [](VsrSettings *s) { return vsr_settings_set_schedule_beta(s, -0.1); },
         VSR_STATUS_INVALID_ARGUMENT, "beta"},
        {"beta_nan", [](VsrSettings *s) { return vsr_settings_set_schedule_beta(s, kNaN); },
         VSR_STATUS_NON_FINITE, "beta"},
        {"mu_min_negative", [](VsrSettings *s) { return vsr_settings_set_schedule_mu_min(s, -1e-9); },
         VSR_STATUS_INVALID_ARGUMENT, "mu_min"},
        {"eta_zero", [](VsrSettings *s) { return vsr_settings_set_schedule_eta(s, 0.0); },
         VSR_STATUS_INVALID_ARGUMENT, "eta"},
        {"pull_negative", [](VsrSettings *s) { return vsr_settings_set_schedule_pull(s, -1.0); },
         VSR_STATUS_INVALID_ARGUMENT, "pull"},
        {"pull_inf", [](VsrSettings *s) { return vsr_settings_set_schedule_pull(s, kInf); },
         VSR_STATUS_NON_FINITE, "pull"},
        {"proximal_weight_negative",
         [](VsrSettings *s) { return vsr_settings_set_proximal_weight(s, -1.0); },
         VSR_STATUS_INVALID_ARGUMENT, "weight"},
        {"odt_free_boundary_two",
         [](VsrSettings *s) { return vsr_settings_set_odt_free_boundary(s, 2); },
         VSR_STATUS_INVALID_ARGUMENT, "enable"},
        {"progress_null_settings",
         [](VsrSettings *) { return vsr_settings_set_progress(nullptr, nullptr, nullptr); },
         VSR_STATUS_NULL_POINTER, "settings"},
    };
}

void PrintTo(const SetterCase &c, std::ostream *os) { *os << c.name; }

class Setter : public ::testing::TestWithParam<SetterCase> {};

TEST_P(Setter, FailsCleanlyAndKeepsTheSettings) {
    const SetterCase &c = GetParam();
    voussoir::Mesh mesh = square();
    voussoir::Settings settings;
    const std::vector<double> before = analyse_q(mesh.get(), settings.get());
    EXPECT_TRUE(Fails(c.call(settings.get()), c.want, c.argument));
    EXPECT_EQ(analyse_q(mesh.get(), settings.get()), before) << "settings changed by a failure";
}

INSTANTIATE_TEST_SUITE_P(Contract, Setter, ::testing::ValuesIn(setter_cases()),
                         [](const auto &info) { return std::string(info.param.name); });

TEST(Setter, ValidValuesAreAccepted) {
    voussoir::Settings s;
    EXPECT_TRUE(Succeeds(vsr_settings_set_tolerance(s.get(), 1e-8)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_q_min(s.get(), 0.0, VSR_BOUND_KIND_ABSOLUTE)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_q_max(s.get(), kInf, VSR_BOUND_KIND_RELATIVE)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_q_min_scope(s.get(), VSR_EDGE_SCOPE_INTERIOR)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_tau_mode(s.get(), VSR_TAU_MODE_ZERO)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_hole_mode(s.get(), VSR_HOLE_MODE_AFFINE)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_load_rule(s.get(), VSR_LOAD_RULE_PLAN_AREA)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_formulation(s.get(), VSR_FORMULATION_EDGE_BASED)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_schedule_beta(s.get(), 0.0)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_schedule_beta(s.get(), 1.0)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_odt_free_boundary(s.get(), 1)));
    EXPECT_TRUE(Succeeds(vsr_settings_set_progress(s.get(), nullptr, nullptr)));
}

// ---------------------------------------------------------------------------------------------
// Mesh setters: status, message, and the mesh keeps its previous loads.

struct MeshSetterCase {
    const char *name;
    std::function<VsrStatus(VsrMesh *)> call;
    VsrStatus want;
    const char *argument;
};

std::vector<MeshSetterCase> mesh_setter_cases() {
    static const std::vector<double> density_negative = {1, 1, -1, 1};
    static const std::vector<double> density_nan = {1, kNaN, 1, 1};
    static const std::vector<double> loads_nan = {0, 0, 0, 0, kNaN};
    static const std::vector<double> loads = {0, 0, 0, 0, 1};
    static const std::vector<double> tau_negative = {0, 0, 0, 0, -1};
    static const std::vector<double> forces_on_anchor = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    return {
        {"density_null_mesh",
         [](VsrMesh *) { return vsr_mesh_set_face_density(nullptr, density_nan.data(), 4); },
         VSR_STATUS_NULL_POINTER, "mesh"},
        {"density_null", [](VsrMesh *m) { return vsr_mesh_set_face_density(m, nullptr, 4); },
         VSR_STATUS_NULL_POINTER, "density"},
        {"density_negative",
         [](VsrMesh *m) { return vsr_mesh_set_face_density(m, density_negative.data(), 4); },
         VSR_STATUS_INVALID_ARGUMENT, "density"},
        {"density_nan",
         [](VsrMesh *m) { return vsr_mesh_set_face_density(m, density_nan.data(), 4); },
         VSR_STATUS_NON_FINITE, "density"},
        {"density_short",
         [](VsrMesh *m) { return vsr_mesh_set_face_density(m, density_negative.data(), 3); },
         VSR_STATUS_INVALID_ARGUMENT, "n_faces"},
        {"extra_loads_nan",
         [](VsrMesh *m) { return vsr_mesh_set_extra_loads(m, loads_nan.data(), 5); },
         VSR_STATUS_NON_FINITE, "loads"},
        {"extra_loads_null", [](VsrMesh *m) { return vsr_mesh_set_extra_loads(m, nullptr, 5); },
         VSR_STATUS_NULL_POINTER, "loads"},
        {"extra_loads_long",
         [](VsrMesh *m) { return vsr_mesh_set_extra_loads(m, loads.data(), 6); },
         VSR_STATUS_INVALID_ARGUMENT, "n_vertices"},
        {"horizontal_forces_overflow",
         [](VsrMesh *m) { return vsr_mesh_set_horizontal_forces(m, loads.data(), kMax); },
         VSR_STATUS_LENGTH_OVERFLOW, "forces"},
        {"horizontal_force_on_anchor",
         [](VsrMesh *m) { return vsr_mesh_set_horizontal_forces(m, forces_on_anchor.data(), 5); },
         VSR_STATUS_INVALID_ARGUMENT, "forces"},
        {"tau_negative",
         [](VsrMesh *m) { return vsr_mesh_set_prescribed_tau(m, tau_negative.data(), 5); },
         VSR_STATUS_INVALID_ARGUMENT, "tau"},
    };
}

void PrintTo(const MeshSetterCase &c, std::ostream *os) { *os << c.name; }

class MeshSetter : public ::testing::TestWithParam<MeshSetterCase> {};

TEST_P(MeshSetter, FailsCleanlyAndKeepsTheMesh) {
    const MeshSetterCase &c = GetParam();
    voussoir::Mesh mesh = square();
    voussoir::Settings settings;
    const std::vector<double> before = analyse_q(mesh.get(), settings.get());
    EXPECT_TRUE(Fails(c.call(mesh.get()), c.want, c.argument));
    EXPECT_EQ(analyse_q(mesh.get(), settings.get()), before) << "mesh changed by a failure";
}

INSTANTIATE_TEST_SUITE_P(Contract, MeshSetter, ::testing::ValuesIn(mesh_setter_cases()),
                         [](const auto &info) { return std::string(info.param.name); });

// ---------------------------------------------------------------------------------------------
// Solves and result getters.

TEST(Contract, DestroyNullDoesNothingAndKeepsTheLastError) {
    VsrMesh *out = kSentinelMesh;
    ASSERT_NE(vsr_mesh_create(nullptr, kV, kTriangles.data(), kF, kAnchored.data(), 4, &out),
              VSR_STATUS_OK);
    const std::string message = vsr_last_error_message();
    ASSERT_FALSE(message.empty());
    vsr_mesh_destroy(nullptr);
    vsr_settings_destroy(nullptr);
    vsr_result_destroy(nullptr);
    EXPECT_EQ(message, vsr_last_error_message());
    EXPECT_STREQ(vsr_status_name(VSR_STATUS_OK), "VSR_STATUS_OK");
    EXPECT_EQ(message, vsr_last_error_message());
}

TEST(Contract, SolvesRejectNullAndLeaveTheOutputAlone) {
    voussoir::Mesh mesh = square();
    voussoir::Settings settings;
    VsrResult *out = kSentinelResult;
    EXPECT_TRUE(Fails(vsr_analyse(nullptr, settings.get(), &out), VSR_STATUS_NULL_POINTER, "mesh"));
    EXPECT_TRUE(Fails(vsr_analyse(mesh.get(), nullptr, &out), VSR_STATUS_NULL_POINTER, "settings"));
    EXPECT_TRUE(Fails(vsr_analyse(mesh.get(), settings.get(), nullptr), VSR_STATUS_NULL_POINTER, "out"));
    EXPECT_TRUE(Fails(vsr_form_find(nullptr, settings.get(), &out), VSR_STATUS_NULL_POINTER, "mesh"));
    EXPECT_TRUE(Fails(vsr_form_find(mesh.get(), nullptr, &out), VSR_STATUS_NULL_POINTER, "settings"));
    EXPECT_TRUE(Fails(vsr_form_find(mesh.get(), settings.get(), nullptr), VSR_STATUS_NULL_POINTER, "out"));
    EXPECT_EQ(out, kSentinelResult);
    VsrSettings *s = kSentinelSettings;
    EXPECT_TRUE(Fails(vsr_settings_create(nullptr), VSR_STATUS_NULL_POINTER, "out"));
    EXPECT_EQ(s, kSentinelSettings);
    // Density 0 everywhere: nothing to balance.
    const std::vector<double> zeros(kF, 0.0), ones(kF, 1.0);
    EXPECT_TRUE(Succeeds(vsr_mesh_set_face_density(mesh.get(), zeros.data(), kF)));
    EXPECT_TRUE(Fails(vsr_analyse(mesh.get(), settings.get(), &out), VSR_STATUS_INVALID_ARGUMENT,
                      "loads"));
    EXPECT_TRUE(Fails(vsr_form_find(mesh.get(), settings.get(), &out),
                      VSR_STATUS_INVALID_ARGUMENT, "loads"));
    EXPECT_EQ(out, kSentinelResult);
    EXPECT_TRUE(Succeeds(vsr_mesh_set_face_density(mesh.get(), ones.data(), kF)));
    // Reuse after the failed calls.
    EXPECT_TRUE(Succeeds(vsr_analyse(mesh.get(), settings.get(), &out)));
    voussoir::Result result(out);
    EXPECT_NE(out, kSentinelResult);
}

class Getters : public ::testing::Test {
  protected:
    void SetUp() override {
        mesh_ = square();
        settings_ = voussoir::Settings();
        VsrResult *raw = nullptr;
        voussoir::check(vsr_analyse(mesh_.get(), settings_.get(), &raw));
        result_ = voussoir::Result(raw);
    }
    voussoir::Mesh mesh_;
    voussoir::Settings settings_;
    voussoir::Result result_;
};

// Every copy-out getter of doubles: #V×3, #E, #V, #V, #V, #V×2, #V, #V, #V×2, #F×2, #S×4.
TEST_F(Getters, ShortBuffersAreReportedAndUntouched) {
    using Getter = VsrStatus (*)(const VsrResult *, double *, std::size_t, std::size_t *);
    const std::vector<std::pair<const char *, Getter>> getters = {
        {"positions", vsr_result_positions},
        {"force_densities", vsr_result_force_densities},
        {"airy", vsr_result_airy},
        {"weights", vsr_result_weights},
        {"tau", vsr_result_tau},
        {"external_horizontal", vsr_result_external_horizontal},
        {"loads", vsr_result_loads},
        {"residuals", vsr_result_residuals},
        {"horizontal_imbalance", vsr_result_horizontal_imbalance},
        {"force_diagram_centres", vsr_result_force_diagram_centres},
        {"force_diagram_segments", vsr_result_force_diagram_segments},
    };
    for (const auto &[name, get] : getters) {
        SCOPED_TRACE(name);
        std::size_t needed = 0;
        ASSERT_TRUE(Succeeds(get(result_.get(), nullptr, 0, &needed)));
        ASSERT_GT(needed, 0u);
        std::vector<double> buffer(needed + 4, -7.0);
        std::size_t reported = 12345;
        EXPECT_TRUE(Fails(get(result_.get(), buffer.data(), needed - 1, &reported),
                          VSR_STATUS_BUFFER_TOO_SMALL, "len"));
        EXPECT_EQ(reported, needed);
        for (double x : buffer) EXPECT_EQ(x, -7.0);
        EXPECT_TRUE(Fails(get(result_.get(), nullptr, 3, &reported), VSR_STATUS_NULL_POINTER, "out"));
        EXPECT_TRUE(Fails(get(nullptr, buffer.data(), buffer.size(), &reported),
                          VSR_STATUS_NULL_POINTER, "result"));
        EXPECT_TRUE(Succeeds(get(result_.get(), buffer.data(), buffer.size(), nullptr)));
        for (std::size_t i = needed; i < buffer.size(); ++i) EXPECT_EQ(buffer[i], -7.0);
    }
    std::size_t needed = 0;
    uint32_t ids[3] = {7, 7, 7};
    EXPECT_TRUE(Fails(vsr_result_edges(result_.get(), ids, 3, &needed), VSR_STATUS_BUFFER_TOO_SMALL, "len"));
    EXPECT_EQ(needed, 2u * 8u);   // 8 edges
    EXPECT_EQ(ids[0], 7u);
    EXPECT_TRUE(Fails(vsr_mesh_edges(mesh_.get(), ids, 3, &needed), VSR_STATUS_BUFFER_TOO_SMALL, "len"));
    EXPECT_EQ(needed, 16u);
}

TEST_F(Getters, FormFindingQuantitiesAreNotAvailableForAnAnalysis) {
    double buffer[4] = {-1, -1, -1, -1};
    std::size_t needed = 99;
    EXPECT_TRUE(Fails(vsr_result_eps_history(result_.get(), buffer, 4, &needed),
                      VSR_STATUS_NOT_AVAILABLE, "result"));
    VsrTermination termination = VSR_TERMINATION_CANCELLED;
    std::size_t iterations = 99;
    EXPECT_TRUE(Fails(vsr_result_termination(result_.get(), &termination, &iterations),
                      VSR_STATUS_NOT_AVAILABLE, "result"));
    EXPECT_EQ(termination, VSR_TERMINATION_CANCELLED);
    EXPECT_EQ(iterations, 99u);
    double h = -1, l2 = -1;
    EXPECT_TRUE(Fails(vsr_result_distances(result_.get(), &h, &l2), VSR_STATUS_NOT_AVAILABLE, "result"));
    EXPECT_EQ(h, -1.0);
    EXPECT_EQ(buffer[0], -1.0);
}

TEST_F(Getters, NullOutPointersAreRejectedWithoutWriting) {
    VsrStressStatus status = VSR_STRESS_STATUS_NUMERICAL_ERROR;
    double eps = -1, objective = -1;
    std::size_t qp = 77;
    EXPECT_TRUE(Fails(vsr_result_stress_summary(result_.get(), &status, &eps, nullptr, &qp),
                      VSR_STATUS_NULL_POINTER, "objective"));
    EXPECT_EQ(status, VSR_STRESS_STATUS_NUMERICAL_ERROR);
    EXPECT_EQ(eps, -1.0);
    EXPECT_EQ(qp, 77u);
    std::size_t v = 1, e = 1, f = 1, h = 1;
    EXPECT_TRUE(Fails(vsr_result_counts(result_.get(), &v, &e, nullptr, &h), VSR_STATUS_NULL_POINTER, "n_faces"));
    EXPECT_TRUE(Fails(vsr_mesh_counts(mesh_.get(), nullptr, &e, &f, &h), VSR_STATUS_NULL_POINTER, "n_vertices"));
    EXPECT_EQ(v + e + f + h, 4u);
    EXPECT_TRUE(Succeeds(vsr_result_stress_summary(result_.get(), &status, &eps, &objective, &qp)));
    EXPECT_EQ(status, VSR_STRESS_STATUS_SOLVED);
    EXPECT_TRUE(Succeeds(vsr_mesh_counts(mesh_.get(), &v, &e, &f, &h)));
    EXPECT_EQ(v, 5u);
    EXPECT_EQ(e, 8u);
    EXPECT_EQ(f, 4u);
    EXPECT_EQ(h, 0u);
}

TEST(Contract, StatusNamesAndVersions) {
    const std::vector<std::pair<VsrStatus, const char *>> names = {
        {VSR_STATUS_OK, "VSR_STATUS_OK"},
        {VSR_STATUS_NULL_POINTER, "VSR_STATUS_NULL_POINTER"},
        {VSR_STATUS_INVALID_ARGUMENT, "VSR_STATUS_INVALID_ARGUMENT"},
        {VSR_STATUS_LENGTH_OVERFLOW, "VSR_STATUS_LENGTH_OVERFLOW"},
        {VSR_STATUS_INDEX_OUT_OF_RANGE, "VSR_STATUS_INDEX_OUT_OF_RANGE"},
        {VSR_STATUS_NON_FINITE, "VSR_STATUS_NON_FINITE"},
        {VSR_STATUS_INVALID_ENUM, "VSR_STATUS_INVALID_ENUM"},
        {VSR_STATUS_BUFFER_TOO_SMALL, "VSR_STATUS_BUFFER_TOO_SMALL"},
        {VSR_STATUS_EMPTY_MESH, "VSR_STATUS_EMPTY_MESH"},
        {VSR_STATUS_INVALID_TOPOLOGY, "VSR_STATUS_INVALID_TOPOLOGY"},
        {VSR_STATUS_INVALID_PLAN, "VSR_STATUS_INVALID_PLAN"},
        {VSR_STATUS_NO_SUPPORT, "VSR_STATUS_NO_SUPPORT"},
        {VSR_STATUS_NOT_AVAILABLE, "VSR_STATUS_NOT_AVAILABLE"},
        {VSR_STATUS_NUMERICAL, "VSR_STATUS_NUMERICAL"},
        {VSR_STATUS_PANIC, "VSR_STATUS_PANIC"},
    };
    for (const auto &[status, name] : names) EXPECT_STREQ(vsr_status_name(status), name);
    EXPECT_STREQ(vsr_status_name(987654), "VSR_STATUS_UNKNOWN");
    EXPECT_STREQ(vsr_status_name(14), "VSR_STATUS_UNKNOWN");
    EXPECT_STREQ(vsr_version(), VSR_VERSION_STRING);
    EXPECT_EQ(vsr_abi_version(), uint32_t{VSR_ABI_VERSION});
    EXPECT_EQ(std::to_string(VSR_VERSION_MAJOR) + "." + std::to_string(VSR_VERSION_MINOR) + "." +
                  std::to_string(VSR_VERSION_PATCH),
              VSR_VERSION_STRING);
}

TEST(Contract, LastErrorIsPerThread) {
    VsrMesh *out = nullptr;
    ASSERT_NE(vsr_mesh_create(nullptr, kV, kTriangles.data(), kF, kAnchored.data(), 4, &out),
              VSR_STATUS_OK);
    const std::string here = vsr_last_error_message();
    std::string there = "unset";
    std::thread([&] {
        there = vsr_last_error_message();   // a fresh thread has no error
        voussoir::Settings s;
        (void)vsr_settings_set_tolerance(s.get(), -1.0);
    }).join();
    EXPECT_EQ(there, "");
    EXPECT_EQ(here, vsr_last_error_message());
}

// ---------------------------------------------------------------------------------------------
// Concurrency through the C API (voussoir.hpp owns the handles).

TEST(Contract, ConcurrentSolvesOnSharedConstHandlesAgree) {
    MeshData dome = vsrt::generated("disk_off_centre_hole");
    const voussoir::Mesh mesh = vsrt::make_mesh(dome);
    const voussoir::Settings settings;
    const VsrMesh *m = mesh.get();
    const VsrSettings *s = settings.get();
    std::vector<double> q[2];
    std::atomic<int> failures{0};
    std::vector<std::thread> threads;
    for (int k = 0; k < 2; ++k)
        threads.emplace_back([&, k] {
            try {
                q[k] = analyse_q(m, s);
            } catch (...) {
                ++failures;
            }
        });
    for (auto &t : threads) t.join();
    EXPECT_EQ(failures.load(), 0);
    EXPECT_EQ(q[0], q[1]);
    EXPECT_EQ(q[0], analyse_q(m, s));
}

}  // namespace
