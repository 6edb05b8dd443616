/*
 * Warm re-solve after an edit through the installed C library: vsr_form_find_from refuses
 * a previous result that does not fit (NULL, an analysis, another mesh, the paper's loop),
 * naming the argument and leaving `out` untouched; after one vertex of a dome is raised by
 * 1% of the plan diagonal it converges, in equilibrium and in fewer stress steps than
 * vsr_form_find of the edited mesh, with the supports where the edited mesh has them. Built
 * like hostile.c (examples/CMakeLists.txt, .ci/cmake-checks.sh); prints one line per failure
 * and exits non-zero if any.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <voussoir.h>

#include "check.h"

#define RINGS 6
#define SECTORS 16
#define N_VERTICES (1 + RINGS * SECTORS)
#define N_TRIANGLES (SECTORS + 2 * (RINGS - 1) * SECTORS)

static uint32_t id(int ring, int sector) {
    return (uint32_t)(1 + (ring - 1) * SECTORS + sector % SECTORS);
}

/* A dome over the unit disk, heights with a gentle bump, its quads split along alternating
 * diagonals (all along one would admit no stress with q >= q_min > 0); outer ring anchored. */
static void dome(double p[3 * N_VERTICES], uint32_t t[3 * N_TRIANGLES], uint32_t rim[SECTORS]) {
    int r, s, k = 0;
    p[0] = 0.0, p[1] = 0.0, p[2] = 0.5;
    for (r = 1; r <= RINGS; ++r) {
        for (s = 0; s < SECTORS; ++s) {
            const double a = 6.283185307179586 * s / SECTORS, rr = (double)r / RINGS;
            double *q = p + 3 * id(r, s);
            q[0] = rr * cos(a), q[1] = rr * sin(a);
            q[2] = 0.5 * (1.0 - rr * rr) + 0.02 * sin(3.0 * a) * rr * (1.0 - rr);
        }
    }
    for (s = 0; s < SECTORS; ++s) {
        t[k++] = 0, t[k++] = id(1, s), t[k++] = id(1, s + 1);
    }
    for (r = 1; r < RINGS; ++r) {
        for (s = 0; s < SECTORS; ++s) {
            if ((r + s) % 2 == 0) {
                t[k++] = id(r, s), t[k++] = id(r + 1, s), t[k++] = id(r + 1, s + 1);
                t[k++] = id(r, s), t[k++] = id(r + 1, s + 1), t[k++] = id(r, s + 1);
            } else {
                t[k++] = id(r, s), t[k++] = id(r + 1, s), t[k++] = id(r, s + 1);
                t[k++] = id(r + 1, s), t[k++] = id(r + 1, s + 1), t[k++] = id(r, s + 1);
            }
        }
    }
    for (s = 0; s < SECTORS; ++s) rim[s] = id(RINGS, s);
}

int main(void) {
    VsrResult *const sentinel = (VsrResult *)(uintptr_t)0xdeadbee8u;
    static double p[3 * N_VERTICES], out_positions[3 * N_VERTICES];
    static uint32_t t[3 * N_TRIANGLES], rim[SECTORS];
    VsrMesh *mesh = NULL, *edited = NULL, *square = NULL;
    VsrSettings *settings = NULL;
    VsrResult *previous = NULL, *analysis = NULL, *warm = NULL, *cold = NULL, *out = sentinel;
    VsrTermination end;
    VsrStressStatus status;
    size_t warm_steps = 0, cold_steps = 0, qp_iterations, needed, v;
    double eps_inf, objective;

    dome(p, t, rim);
    EXPECT(vsr_mesh_create(p, N_VERTICES, t, N_TRIANGLES, rim, SECTORS, &mesh), VSR_STATUS_OK, "");
    EXPECT(vsr_mesh_create(positions, 5, triangles, 4, anchored, 4, &square), VSR_STATUS_OK, "");
    EXPECT(vsr_settings_create(&settings), VSR_STATUS_OK, "");
    EXPECT(vsr_form_find(mesh, settings, &previous), VSR_STATUS_OK, "");
    EXPECT(vsr_analyse(mesh, settings, &analysis), VSR_STATUS_OK, "");

    /* What does not fit is refused, `out` untouched. */
    EXPECT(vsr_form_find_from(mesh, settings, NULL, &out), VSR_STATUS_NULL_POINTER, "previous");
    EXPECT(vsr_form_find_from(mesh, settings, previous, NULL), VSR_STATUS_NULL_POINTER, "out");
    EXPECT(vsr_form_find_from(mesh, settings, analysis, &out), VSR_STATUS_INVALID_ARGUMENT,
           "previous");
    TRUE(strstr(vsr_last_error_message(), "vsr_analyse") != NULL);
    EXPECT(vsr_form_find_from(square, settings, previous, &out), VSR_STATUS_INVALID_ARGUMENT,
           "previous");
    TRUE(strstr(vsr_last_error_message(), "vertices") != NULL);
    EXPECT(vsr_settings_set_method(settings, VSR_METHOD_PAPER), VSR_STATUS_OK, "");
    EXPECT(vsr_form_find_from(mesh, settings, previous, &out), VSR_STATUS_INVALID_ARGUMENT,
           "method");
    EXPECT(vsr_settings_set_method(settings, VSR_METHOD_NEAREST), VSR_STATUS_OK, "");
    TRUE(out == sentinel);

    /* The crown raised by 1% of the plan diagonal (2): warm from the previous answer, and
     * cold. */
    p[2] += 0.02;
    EXPECT(vsr_mesh_create(p, N_VERTICES, t, N_TRIANGLES, rim, SECTORS, &edited), VSR_STATUS_OK,
           "");
    EXPECT(vsr_form_find_from(edited, settings, previous, &warm), VSR_STATUS_OK, "");
    EXPECT(vsr_form_find(edited, settings, &cold), VSR_STATUS_OK, "");
    EXPECT(vsr_result_termination(warm, &end, &warm_steps), VSR_STATUS_OK, "");
    TRUE(end == VSR_TERMINATION_CONVERGED);
    EXPECT(vsr_result_termination(cold, &end, &cold_steps), VSR_STATUS_OK, "");
    TRUE(end == VSR_TERMINATION_CONVERGED);
    TRUE(warm_steps > 0 && warm_steps < cold_steps);
    EXPECT(vsr_result_stress_summary(warm, &status, &eps_inf, &objective, &qp_iterations),
           VSR_STATUS_OK, "");
    TRUE(status == VSR_STRESS_STATUS_SOLVED && eps_inf < 1e-6);
    EXPECT(vsr_result_positions(warm, out_positions, 3 * N_VERTICES, &needed), VSR_STATUS_OK, "");
    TRUE(needed == 3 * N_VERTICES);
    for (v = 0; v < SECTORS; ++v) {
        TRUE(out_positions[3 * rim[v] + 2] == p[3 * rim[v] + 2]);
    }
    /* The previous result is still whole: a second re-solve from it works too. */
    vsr_result_destroy(warm);
    warm = NULL;
    EXPECT(vsr_form_find_from(edited, settings, previous, &warm), VSR_STATUS_OK, "");
    EXPECT(vsr_result_termination(warm, &end, &warm_steps), VSR_STATUS_OK, "");
    TRUE(end == VSR_TERMINATION_CONVERGED);

    vsr_result_destroy(warm);
    vsr_result_destroy(cold);
    vsr_result_destroy(analysis);
    vsr_result_destroy(previous);
    vsr_settings_destroy(settings);
    vsr_mesh_destroy(edited);
    vsr_mesh_destroy(square);
    vsr_mesh_destroy(mesh);
    printf("%d checks, %d failures\n", checks, failures);
    return failures != 0;
}
