/*
 * Voussoir from C: a dome built from flat arrays, form found, its residual printed.
 *
 *   dome [input.obj [result.obj]]
 *
 * The plan is a disk of radius 1 (a centre vertex and RINGS rings of SEGMENTS vertices, odd
 * rings turned by half a step); the rim is anchored. The heights start as a shallow cap that
 * does not stand (a 60° cap squashed to 30% of its height); form finding moves them until it
 * does. Optional arguments write the input and the form-found dome as OBJ files.
 *
 * Exit status: 0 when form finding converged, 1 otherwise.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <voussoir.h>

#define RINGS 6
#define SEGMENTS 16
#define N_VERTICES (1 + RINGS * SEGMENTS)
#define N_TRIANGLES (SEGMENTS * (2 * RINGS - 1))

static uint32_t vertex_id(uint32_t ring, uint32_t m) {
    return 1 + (ring - 1) * SEGMENTS + m % SEGMENTS;
}

static void build_dome(double *positions, uint32_t *triangles, uint32_t *anchored) {
    const double pi = 3.14159265358979323846;
    const double angle = pi / 3.0; /* slope of the cap at the rim */
    const double sphere = 1.0 / sin(angle);
    size_t t = 0;
    positions[0] = 0.0;
    positions[1] = 0.0;
    positions[2] = 0.3 * (sphere - sphere * cos(angle));
    for (uint32_t k = 1; k <= RINGS; ++k) {
        double r = (double)k / RINGS;
        double z = 0.3 * (sqrt(sphere * sphere - r * r) - sphere * cos(angle));
        for (uint32_t m = 0; m < SEGMENTS; ++m) {
            double a = 2.0 * pi * (m + 0.5 * (k % 2)) / SEGMENTS;
            double *p = positions + 3 * vertex_id(k, m);
            p[0] = r * cos(a);
            p[1] = r * sin(a);
            p[2] = z;
        }
    }
    for (uint32_t m = 0; m < SEGMENTS; ++m) {
        uint32_t tri[3] = {0, vertex_id(1, m), vertex_id(1, m + 1)};
        for (int c = 0; c < 3; ++c) triangles[t++] = tri[c];
    }
    for (uint32_t k = 1; k < RINGS; ++k) {
        for (uint32_t m = 0; m < SEGMENTS; ++m) {
            uint32_t a0 = vertex_id(k, m), a1 = vertex_id(k, m + 1);
            uint32_t b0 = vertex_id(k + 1, m), b1 = vertex_id(k + 1, m + 1);
            uint32_t tri[6];
            if (k % 2 == 1) { /* inner a0 lies between outer b0 and b1 */
                uint32_t v[6] = {b0, b1, a0, a0, b1, a1};
                for (int c = 0; c < 6; ++c) tri[c] = v[c];
            } else { /* outer b0 lies between inner a0 and a1 */
                uint32_t v[6] = {a0, b0, a1, a1, b0, b1};
                for (int c = 0; c < 6; ++c) tri[c] = v[c];
            }
            for (int c = 0; c < 6; ++c) triangles[t++] = tri[c];
        }
    }
    for (uint32_t m = 0; m < SEGMENTS; ++m) anchored[m] = vertex_id(RINGS, m);
}

static int write_obj(const char *path, const double *positions, size_t n_vertices,
                     const uint32_t *triangles, size_t n_triangles) {
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 0;
    }
    for (size_t v = 0; v < n_vertices; ++v)
        fprintf(f, "v %.17g %.17g %.17g\n", positions[3 * v], positions[3 * v + 1],
                positions[3 * v + 2]);
    for (size_t t = 0; t < n_triangles; ++t)
        fprintf(f, "f %u %u %u\n", triangles[3 * t] + 1, triangles[3 * t + 1] + 1,
                triangles[3 * t + 2] + 1);
    return fclose(f) == 0;
}

/* Fails loudly: the status name and the library's message. */
static int check(VsrStatus status, const char *what) {
    if (status == VSR_STATUS_OK) return 1;
    fprintf(stderr, "%s failed: %s: %s\n", what, vsr_status_name(status),
            vsr_last_error_message());
    return 0;
}

static int progress(void *user, size_t iteration, double eps_inf) {
    (void)user;
    printf("  iteration %2zu  eps_inf = %.3e\n", iteration, eps_inf);
    return 0; /* continue */
}

int main(int argc, char **argv) {
    static double positions[3 * N_VERTICES];
    static uint32_t triangles[3 * N_TRIANGLES];
    static uint32_t anchored[SEGMENTS];
    static double residuals[N_VERTICES];
    static double result_positions[3 * N_VERTICES];
    VsrMesh *mesh = NULL;
    VsrSettings *settings = NULL;
    VsrResult *result = NULL;
    int ok = 0;

    if (vsr_abi_version() != VSR_ABI_VERSION) {
        fprintf(stderr, "libvoussoir ABI %u, header ABI %d\n", vsr_abi_version(), VSR_ABI_VERSION);
        return 2;
    }
    printf("voussoir %s (header %s)\n", vsr_version(), VSR_VERSION_STRING);
    build_dome(positions, triangles, anchored);
    if (argc > 1 && !write_obj(argv[1], positions, N_VERTICES, triangles, N_TRIANGLES)) return 2;

    if (!check(vsr_mesh_create(positions, N_VERTICES, triangles, N_TRIANGLES, anchored, SEGMENTS,
                               &mesh),
               "vsr_mesh_create"))
        goto done;
    if (!check(vsr_settings_create(&settings), "vsr_settings_create")) goto done;
    if (!check(vsr_settings_set_tolerance(settings, 1e-6), "vsr_settings_set_tolerance") ||
        !check(vsr_settings_set_max_iterations(settings, 100), "vsr_settings_set_max_iterations"))
        goto done;
    if (!check(vsr_settings_set_progress(settings, progress, NULL), "vsr_settings_set_progress"))
        goto done;
    printf("form finding a dome: %d vertices, %d triangles, %d supports\n", N_VERTICES,
           N_TRIANGLES, SEGMENTS);
    if (!check(vsr_form_find(mesh, settings, &result), "vsr_form_find")) goto done;

    {
        VsrTermination termination;
        VsrStressStatus stress;
        size_t iterations, qp_iterations, needed;
        double eps_inf, objective, hausdorff, l2, max_residual = 0.0;
        char message[256];
        if (!check(vsr_result_termination(result, &termination, &iterations),
                   "vsr_result_termination") ||
            !check(vsr_result_stress_summary(result, &stress, &eps_inf, &objective, &qp_iterations),
                   "vsr_result_stress_summary") ||
            !check(vsr_result_distances(result, &hausdorff, &l2), "vsr_result_distances") ||
            !check(vsr_result_residuals(result, residuals, N_VERTICES, &needed),
                   "vsr_result_residuals") ||
            !check(vsr_result_termination_message(result, message, sizeof message, &needed),
                   "vsr_result_termination_message"))
            goto done;
        for (size_t v = 0; v < N_VERTICES; ++v)
            if (fabs(residuals[v]) > max_residual) max_residual = fabs(residuals[v]);
        printf("%s after %zu iterations\n", message, iterations);
        printf("eps_inf = %.3e, max |residual| = %.3e, sum of squares = %.3e\n", eps_inf,
               max_residual, objective);
        printf("moved by at most %.3e (RMS %.3e) of the plan diagonal\n", hausdorff, l2);
        ok = termination == VSR_TERMINATION_CONVERGED && stress == VSR_STRESS_STATUS_SOLVED;
    }
    if (argc > 2) {
        size_t needed;
        if (!check(vsr_result_positions(result, result_positions, 3 * N_VERTICES, &needed),
                   "vsr_result_positions") ||
            !write_obj(argv[2], result_positions, N_VERTICES, triangles, N_TRIANGLES))
            ok = 0;
    }

done:
    vsr_result_destroy(result);
    vsr_settings_destroy(settings);
    vsr_mesh_destroy(mesh);
    return ok ? 0 : 1;
}
