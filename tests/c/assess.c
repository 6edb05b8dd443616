/*
 * Masonry assessment through the installed C library: hostile input to the envelope, the
 * assessment settings, vsr_assess and its getters (status, a one-line message naming the
 * argument, untouched outputs), then an assessment whose certificate is checked from the
 * copied-out arrays. Built like hostile.c (examples/CMakeLists.txt, .ci/cmake-checks.sh);
 * prints one line per failure and exits non-zero if any.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <voussoir.h>

#include "check.h"

/* The square lowered (intrados) or raised (extrados) by 0.05 as a surface of its own. */
static void shifted(double dz, double out[15]) {
    int i;
    for (i = 0; i < 15; ++i) out[i] = positions[i] + (i % 3 == 2 ? dz : 0.0);
}

int main(void) {
    VsrEnvelope *const sentinel_envelope = (VsrEnvelope *)(uintptr_t)0xdeadbee8u;
    VsrAssessment *const sentinel_assessment = (VsrAssessment *)(uintptr_t)0xdeadbee8u;
    VsrMesh *mesh = NULL;
    VsrEnvelope *envelope = sentinel_envelope;
    VsrAssessSettings *settings = NULL;
    VsrAssessment *assessment = sentinel_assessment;
    double lower[15], upper[15], buffer[64];
    const double thickness = 0.1, nan_thickness = NAN, bad_count[2] = {0.1, 0.1};
    size_t needed, i;

    vsr_envelope_destroy(NULL);
    vsr_assess_settings_destroy(NULL);
    vsr_assessment_destroy(NULL);
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, anchored, 4, &mesh), VSR_STATUS_OK, "");

    /* Envelopes: NULL in each slot, NaN, wrong counts, thickness <= 0. */
    EXPECT(vsr_envelope_from_thickness(NULL, &thickness, 1, &envelope), VSR_STATUS_NULL_POINTER,
           "mesh");
    EXPECT(vsr_envelope_from_thickness(mesh, NULL, 1, &envelope), VSR_STATUS_NULL_POINTER,
           "thickness");
    EXPECT(vsr_envelope_from_thickness(mesh, &thickness, 1, NULL), VSR_STATUS_NULL_POINTER, "out");
    EXPECT(vsr_envelope_from_thickness(mesh, &nan_thickness, 1, &envelope), VSR_STATUS_NON_FINITE,
           "thickness");
    EXPECT(vsr_envelope_from_thickness(mesh, bad_count, 2, &envelope), VSR_STATUS_INVALID_ARGUMENT,
           "n_thickness");
    {
        const double faces[4] = {0.1, 0.1, 0.0, 0.1};
        EXPECT(vsr_envelope_from_thickness(mesh, faces, 4, &envelope),
               VSR_STATUS_INVALID_ARGUMENT, "thickness");
        TRUE(strstr(vsr_last_error_message(), "face 2") != NULL);
    }
    shifted(-0.05, lower);
    shifted(0.05, upper);
    EXPECT(vsr_envelope_from_surfaces(mesh, upper, 5, triangles, 4, lower, 5, triangles, 4,
                                      &envelope),
           VSR_STATUS_INVALID_ARGUMENT, "intrados");
    EXPECT(vsr_envelope_from_surfaces(mesh, lower, SIZE_MAX, triangles, 4, upper, 5, triangles, 4,
                                      &envelope),
           VSR_STATUS_LENGTH_OVERFLOW, "intrados_positions");
    EXPECT(vsr_envelope_from_surfaces(mesh, lower, 5, triangles, 4, upper, 4, triangles, 4,
                                      &envelope),
           VSR_STATUS_INDEX_OUT_OF_RANGE, "extrados_triangles");
    EXPECT(vsr_envelope_from_surfaces(mesh, lower, 5, triangles, 1, upper, 5, triangles, 4,
                                      &envelope),
           VSR_STATUS_INVALID_ARGUMENT, "intrados");
    TRUE(strstr(vsr_last_error_message(), "does not cover vertex") != NULL);
    TRUE(envelope == sentinel_envelope);
    EXPECT(vsr_envelope_from_surfaces(mesh, lower, 5, triangles, 4, upper, 5, triangles, 4,
                                      &envelope),
           VSR_STATUS_OK, "");
    TRUE(envelope != sentinel_envelope && envelope != NULL);
    needed = 0;
    EXPECT(vsr_envelope_lower(envelope, buffer, 64, &needed), VSR_STATUS_OK, "");
    TRUE(needed == 5 && fabs(buffer[4] - 0.25) < 1e-12);

    /* Springing joints: NULL, wrong length, a negative reach (named with its vertex); the
     * envelope keeps its joints; then no joint (an infinite reach) read back, and the
     * defaults restored. */
    {
        double springing[5], reach[5], bad[5], back[5];
        EXPECT(vsr_envelope_springing(envelope, springing, 5, &needed), VSR_STATUS_OK, "");
        EXPECT(vsr_envelope_reach(envelope, reach, 5, &needed), VSR_STATUS_OK, "");
        TRUE(needed == 5 && springing[0] == buffer[0] && reach[0] > 0 && isfinite(reach[0]));
        EXPECT(vsr_envelope_set_springing(NULL, springing, 5, reach, 5), VSR_STATUS_NULL_POINTER,
               "envelope");
        EXPECT(vsr_envelope_set_springing(envelope, NULL, 5, reach, 5), VSR_STATUS_NULL_POINTER,
               "springing");
        EXPECT(vsr_envelope_set_springing(envelope, springing, 4, reach, 5),
               VSR_STATUS_INVALID_ARGUMENT, "springing");
        memcpy(bad, reach, sizeof bad);
        bad[3] = -1.0;
        EXPECT(vsr_envelope_set_springing(envelope, springing, 5, bad, 5),
               VSR_STATUS_INVALID_ARGUMENT, "reach");
        TRUE(strstr(vsr_last_error_message(), "vertex 3") != NULL);
        EXPECT(vsr_envelope_reach(envelope, back, 5, &needed), VSR_STATUS_OK, "");
        TRUE(memcmp(back, reach, sizeof back) == 0);
        for (i = 0; i < 5; ++i) bad[i] = INFINITY;
        EXPECT(vsr_envelope_set_springing(envelope, springing, 5, bad, 5), VSR_STATUS_OK, "");
        EXPECT(vsr_envelope_reach(envelope, back, 5, &needed), VSR_STATUS_OK, "");
        TRUE(isinf(back[0]) && isinf(back[4]));
        EXPECT(vsr_envelope_set_springing(envelope, springing, 5, reach, 5), VSR_STATUS_OK, "");
    }

    /* Settings: NULL, bad enums, NaN, out of range; the previous values stay. */
    EXPECT(vsr_assess_settings_create(NULL), VSR_STATUS_NULL_POINTER, "out");
    EXPECT(vsr_assess_settings_create(&settings), VSR_STATUS_OK, "");
    EXPECT(vsr_assess_settings_set_objective(NULL, VSR_OBJECTIVE_FIT), VSR_STATUS_NULL_POINTER,
           "settings");
    EXPECT(vsr_assess_settings_set_objective(settings, 99), VSR_STATUS_INVALID_ENUM, "objective");
    EXPECT(vsr_assess_settings_set_fixed_supports(settings, 5), VSR_STATUS_INVALID_ARGUMENT,
           "fixed");
    EXPECT(vsr_assess_settings_set_unit_weight(settings, NAN), VSR_STATUS_NON_FINITE,
           "unit_weight");
    EXPECT(vsr_assess_settings_set_unit_weight(settings, -1.0), VSR_STATUS_INVALID_ARGUMENT,
           "unit_weight");
    EXPECT(vsr_assess_settings_set_load_rule(settings, 9), VSR_STATUS_INVALID_ENUM, "rule");
    EXPECT(vsr_assess_settings_set_load_pattern(settings, NULL, 5), VSR_STATUS_NULL_POINTER,
           "loads");
    EXPECT(vsr_assess_settings_set_q_min(settings, 0.0, 3), VSR_STATUS_INVALID_ENUM, "kind");
    EXPECT(vsr_assess_settings_set_tolerance(settings, 2.0), VSR_STATUS_INVALID_ARGUMENT,
           "tolerance");
    EXPECT(vsr_assess_settings_set_max_iterations(settings, 0), VSR_STATUS_INVALID_ARGUMENT,
           "max_iterations");

    /* vsr_assess: NULL in each slot, max-load without a pattern; out untouched. */
    EXPECT(vsr_assess(NULL, envelope, settings, &assessment), VSR_STATUS_NULL_POINTER, "mesh");
    EXPECT(vsr_assess(mesh, NULL, settings, &assessment), VSR_STATUS_NULL_POINTER, "envelope");
    EXPECT(vsr_assess(mesh, envelope, NULL, &assessment), VSR_STATUS_NULL_POINTER, "settings");
    EXPECT(vsr_assess(mesh, envelope, settings, NULL), VSR_STATUS_NULL_POINTER, "out");
    EXPECT(vsr_assess_settings_set_objective(settings, VSR_OBJECTIVE_MAX_LOAD), VSR_STATUS_OK, "");
    EXPECT(vsr_assess(mesh, envelope, settings, &assessment), VSR_STATUS_INVALID_ARGUMENT,
           "load_pattern");
    TRUE(assessment == sentinel_assessment);

    /* A fit, reused after the failures: certified, read back by copy-out. */
    EXPECT(vsr_assess_settings_set_objective(settings, VSR_OBJECTIVE_FIT), VSR_STATUS_OK, "");
    EXPECT(vsr_assess(mesh, envelope, settings, &assessment), VSR_STATUS_OK, "");
    {
        uint32_t feasible = 7, edges[16], bound_vertex = 7, residual_vertex = 7;
        VsrTermination termination = VSR_TERMINATION_BLOCKED;
        size_t iterations = 0;
        double seconds = -1, scale = -1, safety = -1, thrust = -1, lambda = -1;
        double eps = -1, imbalance = -1, worst = -1, q[8], lo[5], hi[5], residual[5] = {0};
        VsrObjective objective = VSR_OBJECTIVE_MAX_LOAD;
        EXPECT(vsr_assessment_outcome(assessment, &feasible, &termination, &iterations, NULL),
               VSR_STATUS_NULL_POINTER, "seconds");
        TRUE(feasible == 7 && termination == VSR_TERMINATION_BLOCKED);
        EXPECT(vsr_assessment_outcome(assessment, &feasible, &termination, &iterations, &seconds),
               VSR_STATUS_OK, "");
        TRUE(feasible == 1 && termination == VSR_TERMINATION_CONVERGED && seconds >= 0);
        EXPECT(vsr_assessment_objective(assessment, &objective), VSR_STATUS_OK, "");
        TRUE(objective == VSR_OBJECTIVE_FIT);
        EXPECT(vsr_assessment_figures(assessment, &scale, &safety, &thrust, &lambda),
               VSR_STATUS_OK, "");
        TRUE(scale == 1.0 && safety == 1.0 && thrust > 0 && lambda == 0.0);
        EXPECT(vsr_assessment_certificate(assessment, &eps, &imbalance, &worst, &bound_vertex,
                                          &residual_vertex),
               VSR_STATUS_OK, "");
        TRUE(eps < 1e-6 && worst == 0.0 && bound_vertex == VSR_NO_VERTEX && residual_vertex == 4);
        for (i = 0; i < 64; ++i) buffer[i] = -7.0;
        EXPECT(vsr_assessment_positions(assessment, buffer, 14, &needed),
               VSR_STATUS_BUFFER_TOO_SMALL, "len");
        TRUE(needed == 15 && buffer[0] == -7.0);
        EXPECT(vsr_assessment_positions(NULL, buffer, 64, &needed), VSR_STATUS_NULL_POINTER,
               "assessment");
        EXPECT(vsr_assessment_positions(assessment, buffer, 64, &needed), VSR_STATUS_OK, "");
        EXPECT(vsr_assessment_edges(assessment, edges, 16, &needed), VSR_STATUS_OK, "");
        TRUE(needed == 16);
        EXPECT(vsr_assessment_force_densities(assessment, q, 8, &needed), VSR_STATUS_OK, "");
        EXPECT(vsr_assessment_lower(assessment, lo, 5, &needed), VSR_STATUS_OK, "");
        EXPECT(vsr_assessment_upper(assessment, hi, 5, &needed), VSR_STATUS_OK, "");
        /* The certificate from the arrays: the centre balances its load, inside its bounds. */
        {
            double load[5];
            EXPECT(vsr_assessment_loads(assessment, load, 5, &needed), VSR_STATUS_OK, "");
            for (i = 0; i < 8; ++i) {
                uint32_t a = edges[2 * i], b = edges[2 * i + 1];
                TRUE(q[i] >= 0.0);
                residual[a] += q[i] * (buffer[3 * a + 2] - buffer[3 * b + 2]);
                residual[b] += q[i] * (buffer[3 * b + 2] - buffer[3 * a + 2]);
            }
            TRUE(fabs(residual[4] - load[4]) < 1e-6 * load[4]);
        }
        TRUE(buffer[14] >= lo[4] - 1e-9 && buffer[14] <= hi[4] + 1e-9);
    }

    vsr_assessment_destroy(assessment);
    vsr_assess_settings_destroy(settings);
    vsr_envelope_destroy(envelope);
    vsr_mesh_destroy(mesh);
    printf("%d checks, %d failures\n", checks, failures);
    return failures == 0 ? 0 : 1;
}
