/*
 * What the C tests (hostile.c, assess.c) share: EXPECT(call, status, argument) checks a
 * status and that a failure's message names `argument` on one line (a success leaves none),
 * TRUE(condition) checks a condition; each prints a line per failure and counts into
 * `checks` and `failures`. And the mesh both start from.
 */
#ifndef VSR_TESTS_C_CHECK_H
#define VSR_TESTS_C_CHECK_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <voussoir.h>

static int failures = 0;
static int checks = 0;

static void expect(int line, VsrStatus got, VsrStatus want, const char *argument) {
    const char *message = vsr_last_error_message();
    char quoted[64];
    ++checks;
    snprintf(quoted, sizeof quoted, "`%s`", argument);
    if (got != want) {
        printf("line %d: got %s, want %s (%s)\n", line, vsr_status_name(got),
               vsr_status_name(want), message);
        ++failures;
    } else if (want != VSR_STATUS_OK && (message[0] == '\0' || !strstr(message, quoted) ||
                                         strchr(message, '\n'))) {
        printf("line %d: message does not name %s on one line: \"%s\"\n", line, quoted, message);
        ++failures;
    } else if (want == VSR_STATUS_OK && message[0] != '\0') {
        printf("line %d: success left a message: \"%s\"\n", line, message);
        ++failures;
    }
}

static void truth(int line, int condition, const char *what) {
    ++checks;
    if (!condition) {
        printf("line %d: %s\n", line, what);
        ++failures;
    }
}

#define EXPECT(call, status, argument) expect(__LINE__, (call), (status), (argument))
#define TRUE(condition) truth(__LINE__, (condition), #condition)

/* A square of 4 triangles around a raised centre vertex, corners anchored. */
static const double positions[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3};
static const uint32_t triangles[] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
static const uint32_t anchored[] = {0, 1, 2, 3};

#endif
