/*
 * Hostile input through the installed C library: each case checks the status, a non-empty
 * one-line message naming the argument at fault, and untouched outputs. Built against the
 * installed package by examples/CMakeLists.txt and .ci/cmake-checks.sh, and against the build
 * tree by the latter; prints one line per failure and exits non-zero if any.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <voussoir.h>

#include "check.h"

int main(void) {
    VsrMesh *const sentinel_mesh = (VsrMesh *)(uintptr_t)0xdeadbee8u;
    VsrResult *const sentinel_result = (VsrResult *)(uintptr_t)0xdeadbee8u;
    VsrMesh *mesh = sentinel_mesh;
    VsrSettings *settings = NULL;
    VsrResult *result = sentinel_result;
    double nan_positions[15];
    uint32_t bad_triangles[12];
    double buffer[64];
    size_t needed;
    size_t i;

    /* destroy(NULL) */
    vsr_mesh_destroy(NULL);
    vsr_settings_destroy(NULL);
    vsr_result_destroy(NULL);

    /* NULL in each slot of vsr_mesh_create. */
    EXPECT(vsr_mesh_create(NULL, 5, triangles, 4, anchored, 4, &mesh), VSR_STATUS_NULL_POINTER,
           "positions");
    EXPECT(vsr_mesh_create(positions, 5, NULL, 4, anchored, 4, &mesh), VSR_STATUS_NULL_POINTER,
           "triangles");
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, NULL, 4, &mesh), VSR_STATUS_NULL_POINTER,
           "anchored");
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, anchored, 4, NULL), VSR_STATUS_NULL_POINTER,
           "out");
    /* Zero, huge and overflowing lengths: the arrays are never read past their end. */
    EXPECT(vsr_mesh_create(positions, 0, triangles, 4, anchored, 4, &mesh), VSR_STATUS_EMPTY_MESH,
           "positions");
    EXPECT(vsr_mesh_create(positions, SIZE_MAX, triangles, 4, anchored, 4, &mesh),
           VSR_STATUS_LENGTH_OVERFLOW, "positions");
    EXPECT(vsr_mesh_create(positions, SIZE_MAX / 3 + 1, triangles, 4, anchored, 4, &mesh),
           VSR_STATUS_LENGTH_OVERFLOW, "positions");
    EXPECT(vsr_mesh_create(positions, 5, triangles, SIZE_MAX / 2, anchored, 4, &mesh),
           VSR_STATUS_LENGTH_OVERFLOW, "triangles");
    EXPECT(vsr_mesh_create(positions, (size_t)UINT32_MAX + 1, triangles, 4, anchored, 4, &mesh),
           VSR_STATUS_LENGTH_OVERFLOW, "positions");
    /* Out-of-range ids, NaN coordinates. */
    memcpy(bad_triangles, triangles, sizeof triangles);
    bad_triangles[5] = 5;
    EXPECT(vsr_mesh_create(positions, 5, bad_triangles, 4, anchored, 4, &mesh),
           VSR_STATUS_INDEX_OUT_OF_RANGE, "triangles");
    {
        const uint32_t bad_anchors[] = {0, 1, 2, 99};
        EXPECT(vsr_mesh_create(positions, 5, triangles, 4, bad_anchors, 4, &mesh),
               VSR_STATUS_INDEX_OUT_OF_RANGE, "anchored");
    }
    memcpy(nan_positions, positions, sizeof positions);
    nan_positions[13] = NAN;
    EXPECT(vsr_mesh_create(nan_positions, 5, triangles, 4, anchored, 4, &mesh),
           VSR_STATUS_NON_FINITE, "positions");
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, anchored, 0, &mesh), VSR_STATUS_NO_SUPPORT,
           "anchored");
    {
        /* The square twice, the second copy shifted by half its side: stacked in plan. */
        double stacked[30];
        uint32_t stacked_triangles[24];
        const uint32_t stacked_anchors[] = {0, 1, 2, 3, 5, 6, 7, 8};
        memcpy(stacked, positions, sizeof positions);
        memcpy(stacked_triangles, triangles, sizeof triangles);
        for (i = 0; i < 15; ++i) stacked[15 + i] = positions[i] + (i % 3 == 2 ? 1.0 : 0.5);
        for (i = 0; i < 12; ++i) stacked_triangles[12 + i] = triangles[i] + 5;
        EXPECT(vsr_mesh_create(stacked, 10, stacked_triangles, 8, stacked_anchors, 8, &mesh),
               VSR_STATUS_INVALID_PLAN, "positions");
        TRUE(strstr(vsr_last_error_message(), "overlap") != NULL);
    }
    TRUE(mesh == sentinel_mesh);

    /* A valid mesh; the last error is cleared by success but kept by destroy(NULL). */
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, anchored, 4, &mesh), VSR_STATUS_OK, "");
    EXPECT(vsr_settings_create(&settings), VSR_STATUS_OK, "");

    /* Setters: NULL handle, NaN, negative, invalid enum values, wrong lengths. */
    EXPECT(vsr_settings_set_tolerance(NULL, 1e-6), VSR_STATUS_NULL_POINTER, "settings");
    EXPECT(vsr_settings_set_tolerance(settings, NAN), VSR_STATUS_NON_FINITE, "tolerance");
    EXPECT(vsr_settings_set_tolerance(settings, -1.0), VSR_STATUS_INVALID_ARGUMENT, "tolerance");
    EXPECT(vsr_settings_set_q_min(settings, -0.5, VSR_BOUND_KIND_ABSOLUTE),
           VSR_STATUS_INVALID_ARGUMENT, "value");
    EXPECT(vsr_settings_set_q_min(settings, 0.1, 7), VSR_STATUS_INVALID_ENUM, "kind");
    EXPECT(vsr_settings_set_q_max(settings, NAN, VSR_BOUND_KIND_RELATIVE), VSR_STATUS_NON_FINITE,
           "value");
    EXPECT(vsr_settings_set_tau_mode(settings, 42), VSR_STATUS_INVALID_ENUM, "mode");
    EXPECT(vsr_settings_set_hole_mode(settings, 42), VSR_STATUS_INVALID_ENUM, "mode");
    EXPECT(vsr_settings_set_load_rule(settings, 42), VSR_STATUS_INVALID_ENUM, "rule");
    EXPECT(vsr_settings_set_formulation(settings, 42), VSR_STATUS_INVALID_ENUM, "formulation");
    EXPECT(vsr_settings_set_q_min_scope(settings, 42), VSR_STATUS_INVALID_ENUM, "scope");
    EXPECT(vsr_settings_set_max_iterations(settings, 0), VSR_STATUS_INVALID_ARGUMENT,
           "max_iterations");
    EXPECT(vsr_settings_set_schedule_beta(settings, 2.0), VSR_STATUS_INVALID_ARGUMENT, "beta");
    {
        double density[4] = {1, 1, -1, 1};
        double loads[5] = {0, 0, 0, 0, NAN};
        EXPECT(vsr_mesh_set_face_density(mesh, density, 4), VSR_STATUS_INVALID_ARGUMENT,
               "density");
        EXPECT(vsr_mesh_set_face_density(mesh, density, 3), VSR_STATUS_INVALID_ARGUMENT,
               "n_faces");
        EXPECT(vsr_mesh_set_extra_loads(mesh, loads, 5), VSR_STATUS_NON_FINITE, "loads");
        EXPECT(vsr_mesh_set_extra_loads(mesh, NULL, 5), VSR_STATUS_NULL_POINTER, "loads");
        EXPECT(vsr_mesh_set_horizontal_forces(mesh, loads, SIZE_MAX), VSR_STATUS_LENGTH_OVERFLOW,
               "forces");
        EXPECT(vsr_mesh_set_extra_loads(NULL, loads, 5), VSR_STATUS_NULL_POINTER, "mesh");
    }

    /* Solves: NULL in each slot, output untouched. */
    EXPECT(vsr_analyse(NULL, settings, &result), VSR_STATUS_NULL_POINTER, "mesh");
    EXPECT(vsr_analyse(mesh, NULL, &result), VSR_STATUS_NULL_POINTER, "settings");
    EXPECT(vsr_form_find(mesh, settings, NULL), VSR_STATUS_NULL_POINTER, "out");
    TRUE(result == sentinel_result);

    /* Density 0 everywhere: nothing to balance, so no solve; the density is set back after. */
    {
        const double zeros[4] = {0, 0, 0, 0};
        const double ones[4] = {1, 1, 1, 1};
        EXPECT(vsr_mesh_set_face_density(mesh, zeros, 4), VSR_STATUS_OK, "");
        EXPECT(vsr_analyse(mesh, settings, &result), VSR_STATUS_INVALID_ARGUMENT, "loads");
        EXPECT(vsr_form_find(mesh, settings, &result), VSR_STATUS_INVALID_ARGUMENT, "loads");
        EXPECT(vsr_mesh_set_face_density(mesh, ones, 4), VSR_STATUS_OK, "");
    }
    /* Coordinates whose areas double precision cannot hold. */
    {
        double huge[15];
        VsrMesh *huge_mesh = sentinel_mesh;
        for (i = 0; i < 15; ++i) huge[i] = positions[i] * 1e200;
        EXPECT(vsr_mesh_create(huge, 5, triangles, 4, anchored, 4, &huge_mesh),
               VSR_STATUS_INVALID_ARGUMENT, "positions");
        TRUE(huge_mesh == sentinel_mesh);
    }

    /* Reuse after the failed calls: the handles still work. */
    EXPECT(vsr_analyse(mesh, settings, &result), VSR_STATUS_OK, "");
    TRUE(result != sentinel_result && result != NULL);

    /* Short buffers: status, `needed`, untouched buffer. */
    for (i = 0; i < 64; ++i) buffer[i] = -7.0;
    needed = 0;
    EXPECT(vsr_result_positions(result, buffer, 14, &needed), VSR_STATUS_BUFFER_TOO_SMALL, "len");
    TRUE(needed == 15);
    for (i = 0; i < 64; ++i) TRUE(buffer[i] == -7.0);
    EXPECT(vsr_result_positions(result, NULL, 3, &needed), VSR_STATUS_NULL_POINTER, "out");
    EXPECT(vsr_result_positions(NULL, buffer, 64, &needed), VSR_STATUS_NULL_POINTER, "result");
    EXPECT(vsr_result_eps_history(result, buffer, 64, &needed), VSR_STATUS_NOT_AVAILABLE,
           "result");
    for (i = 0; i < 64; ++i) TRUE(buffer[i] == -7.0);
    {
        VsrQpSolver solvers[2] = {VSR_QP_SOLVER_CLARABEL, VSR_QP_SOLVER_CLARABEL};
        EXPECT(vsr_result_step_solvers(result, solvers, 2, &needed), VSR_STATUS_NOT_AVAILABLE,
               "result");
        TRUE(solvers[0] == VSR_QP_SOLVER_CLARABEL && solvers[1] == VSR_QP_SOLVER_CLARABEL);
    }
    EXPECT(vsr_result_positions(result, buffer, 64, &needed), VSR_STATUS_OK, "");
    TRUE(needed == 15 && buffer[14] == 0.3 && buffer[15] == -7.0);
    {
        double eps = -1.0, objective = -1.0;
        size_t qp = 0;
        VsrStressStatus status = VSR_STRESS_STATUS_NUMERICAL_ERROR;
        EXPECT(vsr_result_stress_summary(result, &status, &eps, NULL, &qp),
               VSR_STATUS_NULL_POINTER, "objective");
        TRUE(eps == -1.0 && status == VSR_STRESS_STATUS_NUMERICAL_ERROR);
        EXPECT(vsr_result_stress_summary(result, &status, &eps, &objective, &qp), VSR_STATUS_OK,
               "");
        TRUE(status == VSR_STRESS_STATUS_SOLVED);
    }

    /* Mesh files: bad paths and bad files leave `out` and `n_merged` untouched. */
    {
        static const char bad_off[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
        static const char good_off[] =
            "OFF\n5 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 0.3\n"
            "3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
        static const unsigned char short_stl[90] = {0};
        VsrMesh *read = sentinel_mesh;
        size_t merged = 77;
        FILE *f;
        f = fopen("vsr_hostile_bad.off", "w");
        TRUE(f != NULL);
        if (f) {
            fputs(bad_off, f);
            fclose(f);
        }
        f = fopen("vsr_hostile_short.stl", "wb");
        TRUE(f != NULL);
        if (f) {
            fwrite(short_stl, 1, sizeof short_stl, f);
            fclose(f);
        }
        f = fopen("vsr_hostile_good.off", "w");
        TRUE(f != NULL);
        if (f) {
            fputs(good_off, f);
            fclose(f);
        }
        EXPECT(vsr_mesh_read(NULL, NULL, anchored, 4, 1e-9, 1e-4, &merged, &read),
               VSR_STATUS_NULL_POINTER, "path");
        EXPECT(vsr_mesh_read("vsr_hostile_good.off", NULL, anchored, 4, 1e-9, 1e-4, &merged,
                             NULL),
               VSR_STATUS_NULL_POINTER, "out");
        EXPECT(vsr_mesh_read("vsr_hostile_missing.obj", NULL, anchored, 4, 1e-9, 1e-4, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "path");
        EXPECT(vsr_mesh_read("vsr_hostile_good.xyz", NULL, anchored, 4, 1e-9, 1e-4, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "path");
        EXPECT(vsr_mesh_read("vsr_hostile_bad.off", NULL, anchored, 3, 1e-9, 1e-4, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "path");
        TRUE(strstr(vsr_last_error_message(), "vsr_hostile_bad.off:6:") != NULL);
        EXPECT(vsr_mesh_read("vsr_hostile_short.stl", NULL, anchored, 4, 1e-9, 1e-4, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "path");
        EXPECT(vsr_mesh_read("vsr_hostile_good.off", "vsr_hostile_missing.json", NULL, 0, 1e-9,
                             1e-4, &merged, &read),
               VSR_STATUS_INVALID_ARGUMENT, "supports_path");
        EXPECT(vsr_mesh_read("vsr_hostile_good.off", NULL, anchored, 4, NAN, 1e-4, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "weld_tolerance");
        EXPECT(vsr_mesh_read("vsr_hostile_good.off", NULL, anchored, 4, 1e-9, -1.0, &merged,
                             &read),
               VSR_STATUS_INVALID_ARGUMENT, "repair_tolerance");
        TRUE(read == sentinel_mesh && merged == 77);
        EXPECT(vsr_mesh_read("vsr_hostile_good.off", NULL, anchored, 4, 1e-9, 1e-4, NULL, &read),
               VSR_STATUS_OK, "");
        EXPECT(vsr_result_write(result, read, NULL), VSR_STATUS_NULL_POINTER, "path");
        EXPECT(vsr_result_write(result, read, "vsr_hostile_no_such_dir/out.off"),
               VSR_STATUS_INVALID_ARGUMENT, "path");
        EXPECT(vsr_result_write(result, read, "vsr_hostile_out.off"), VSR_STATUS_OK, "");
        EXPECT(vsr_result_write_solid(NULL, read, 0.01, "vsr_hostile_solid.stl"),
               VSR_STATUS_NULL_POINTER, "result");
        EXPECT(vsr_result_write_solid(result, read, 0.01, NULL), VSR_STATUS_NULL_POINTER, "path");
        EXPECT(vsr_result_write_solid(result, read, -1.0, "vsr_hostile_solid.stl"),
               VSR_STATUS_INVALID_ARGUMENT, "thickness");
        EXPECT(vsr_result_write_solid_from_density(result, read, 0.0, "vsr_hostile_solid.stl"),
               VSR_STATUS_INVALID_ARGUMENT, "unit_weight");
        f = fopen("vsr_hostile_solid.stl", "r");
        TRUE(f == NULL);
        if (f) fclose(f);
        EXPECT(vsr_result_write_solid(result, read, 0.01, "vsr_hostile_solid.stl"), VSR_STATUS_OK,
               "");
        f = fopen("vsr_hostile_solid.stl", "r");
        TRUE(f != NULL);
        if (f) fclose(f);
        remove("vsr_hostile_solid.stl");
        f = fopen("vsr_hostile_out.off", "r");
        TRUE(f != NULL);
        if (f) fclose(f);
        vsr_mesh_destroy(read);
        remove("vsr_hostile_bad.off");
        remove("vsr_hostile_short.stl");
        remove("vsr_hostile_good.off");
        remove("vsr_hostile_out.off");
    }

    /* Names and versions. */
    TRUE(strcmp(vsr_status_name(VSR_STATUS_OK), "VSR_STATUS_OK") == 0);
    TRUE(strcmp(vsr_status_name(VSR_STATUS_BUFFER_TOO_SMALL), "VSR_STATUS_BUFFER_TOO_SMALL") == 0);
    TRUE(strcmp(vsr_status_name(987654), "VSR_STATUS_UNKNOWN") == 0);
    TRUE(strcmp(vsr_version(), VSR_VERSION_STRING) == 0);
    TRUE(vsr_abi_version() == VSR_ABI_VERSION);

    vsr_result_destroy(result);
    vsr_settings_destroy(settings);
    vsr_mesh_destroy(mesh);
    printf("%d checks, %d failures\n", checks, failures);
    return failures == 0 ? 0 : 1;
}
