/* The C interface of subfric checked from C, as a finite-element code calls it.
 *
 * Usage: check_interface CASES_FILE
 *
 * CASES_FILE is written by tests/c_interface.rs from the Rust path (Contact3::step_increment and its
 * consistent tangent). For every case this program builds the model through the C interface
 * (from the parameter struct, a JSON file or a JSON string), steps a material point through
 * the slip increments and checks, at every step:
 *   - the state, traction and tangent against the Rust reference (relative 1e-12);
 *   - the tangent dshear_dslip against its own fourth-order central differences of the step
 *     in each slip component, and dshear_dpressure against differences in the pressure
 *     (relative Frobenius error <= 1e-6);
 *   - that stepping in place (state_in == state_out, as with a state-variable array) gives
 *     the same state.
 * Then it checks the error paths (invalid parameters named, NULL pointers, bad JSON, a
 * missing file, a bad pressure, a short message buffer, a forward axis along the normal, a
 * device as model file, a state that is no state: all zero, or mu beyond the model's bounds)
 * and that a point with a slip record of 1e11 mm steps to the traction of one near 0.
 *
 * Prints one line per case and exits 0 if every check passed, 1 otherwise. */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "subfric.h"

#define FD_TOLERANCE 1e-6
#define REF_TOLERANCE 1e-12
#define MSG_LEN 512

static int failures = 0;
static int checks = 0;

static void check(int ok, const char *what, const char *detail) {
    checks++;
    if (!ok) {
        failures++;
        fprintf(stderr, "FAILED: %s %s\n", what, detail ? detail : "");
    }
}

static int read_token(FILE *f, char *buf, const char *expected) {
    if (fscanf(f, "%255s", buf) != 1) return 0;
    if (expected && strcmp(buf, expected) != 0) {
        fprintf(stderr, "cases file: expected '%s', found '%s'\n", expected, buf);
        exit(2);
    }
    return 1;
}

static double read_double(FILE *f) {
    char buf[256];
    if (fscanf(f, "%255s", buf) != 1) {
        fprintf(stderr, "cases file: a number is missing\n");
        exit(2);
    }
    return strtod(buf, NULL);
}

static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    long n;
    char *text;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = malloc((size_t)n + 1);
    if (fread(text, 1, (size_t)n, f) != (size_t)n) {
        free(text);
        fclose(f);
        return NULL;
    }
    text[n] = '\0';
    fclose(f);
    return text;
}

/* |a - b| against the reference's scale: relative, with the group's norm as a floor. */
static double rel_diff(const double *a, const double *b, int n) {
    double err = 0.0, size = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        err += (a[i] - b[i]) * (a[i] - b[i]);
        size += b[i] * b[i];
    }
    if (size == 0.0) return sqrt(err);
    return sqrt(err / size);
}

/* The state as 13 doubles, as it sits in a state-variable array. */
static void state_values(const SubfricState *s, double v[SUBFRIC_STATE_LEN]) {
    memcpy(v, s, sizeof(double) * SUBFRIC_STATE_LEN);
}

/* Fourth-order central difference of the end-of-step shear: perturbation m * delta of the slip
 * increment along e (or of the pressure when e is NULL). Returns 0 if a perturbed step failed
 * or changed branch (the tangent is one-sided there). */
static int fd4(const SubfricModel *model, const SubfricState *st, const double dslip[3],
               double p, double dt, const double *e, double delta, int branch, double out[3]) {
    static const double m[4] = {-2.0, -1.0, 1.0, 2.0};
    double f[4][3];
    int k, i;
    for (k = 0; k < 4; k++) {
        SubfricState next;
        SubfricResponse r;
        double du[3];
        double pk = p;
        for (i = 0; i < 3; i++) du[i] = dslip[i] + (e ? m[k] * delta * e[i] : 0.0);
        if (!e) pk = p + m[k] * delta;
        if (subfric_step(model, st, du, pk, dt, &next, &r, NULL, 0) != SUBFRIC_STATUS_OK)
            return 0;
        if (r.plastic != branch) return 0;
        for (i = 0; i < 3; i++) f[k][i] = r.shear[i];
    }
    for (i = 0; i < 3; i++)
        out[i] = (f[0][i] - 8.0 * f[1][i] + 8.0 * f[2][i] - f[3][i]) / (12.0 * delta);
    return 1;
}

typedef struct {
    int steps, elastic, plastic, skipped;
    double worst_ref, worst_fd, worst_fd_p;
} Tally;

static void run_case(FILE *f, const char *name) {
    char kind[256], source[256], word[256], msg[MSG_LEN];
    double normal[3], forward[3], p;
    int nsteps, s, i, j;
    SubfricModel *model = NULL;
    SubfricStatus status;
    SubfricState st;
    Tally t = {0, 0, 0, 0, 0.0, 0.0, 0.0};

    read_token(f, kind, "model");
    read_token(f, kind, NULL);
    if (strcmp(kind, "params") == 0) {
        SubfricParams prm;
        prm.mu_s = read_double(f);
        prm.mu_k = read_double(f);
        prm.kappa = read_double(f);
        prm.xi = read_double(f);
        prm.u_tilde = read_double(f);
        prm.alpha_t = read_double(f);
        prm.alpha_n = read_double(f);
        prm.mu_0 = read_double(f);
        read_token(f, source, "normal");
        for (i = 0; i < 3; i++) normal[i] = read_double(f);
        read_token(f, source, "forward");
        for (i = 0; i < 3; i++) forward[i] = read_double(f);
        status = subfric_model_new(&prm, normal, forward, &model, msg, MSG_LEN);
    } else {
        read_token(f, source, NULL);
        read_token(f, word, "normal");
        for (i = 0; i < 3; i++) normal[i] = read_double(f);
        read_token(f, word, "forward");
        for (i = 0; i < 3; i++) forward[i] = read_double(f);
        if (strcmp(kind, "file") == 0) {
            status = subfric_model_from_file(source, normal, forward, &model, msg, MSG_LEN);
        } else {
            char *text = read_file(source);
            check(text != NULL, name, "cannot read the JSON file");
            status = subfric_model_from_json(text, normal, forward, &model, msg, MSG_LEN);
            free(text);
        }
    }
    check(status == SUBFRIC_STATUS_OK && model != NULL, name, msg);
    if (!model) exit(1);
    read_token(f, source, "pressure");
    p = read_double(f);
    read_token(f, source, "steps");
    nsteps = (int)read_double(f);

    status = subfric_state_init(model, &st, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_OK && st.r == 0.0 && st.shear[0] == 0.0, name, "state_init");

    for (s = 0; s < nsteps; s++) {
        double dslip[3], dt, ref_state[SUBFRIC_STATE_LEN], ref_tangent[9], ref_dp[3],
            ref_plastic_slip[3], got_state[SUBFRIC_STATE_LEN], d, du, delta, fd[9], dp[3],
            col[3], e[3], traction[3], err, size;
        int ref_plastic, ok = 1;
        SubfricState next, inplace;
        SubfricResponse r;
        char detail[640];

        read_token(f, source, "step");
        for (i = 0; i < 3; i++) dslip[i] = read_double(f);
        dt = read_double(f);
        for (i = 0; i < SUBFRIC_STATE_LEN; i++) ref_state[i] = read_double(f);
        for (i = 0; i < 9; i++) ref_tangent[i] = read_double(f);
        for (i = 0; i < 3; i++) ref_dp[i] = read_double(f);
        for (i = 0; i < 3; i++) ref_plastic_slip[i] = read_double(f);
        ref_plastic = (int)read_double(f);

        status = subfric_step(model, &st, dslip, p, dt, &next, &r, msg, MSG_LEN);
        snprintf(detail, sizeof detail, "step %d: %s", s, msg);
        check(status == SUBFRIC_STATUS_OK, name, detail);
        if (status != SUBFRIC_STATUS_OK) break;

        /* Against the Rust path. */
        state_values(&next, got_state);
        d = rel_diff(got_state, ref_state, 3);                              /* slip */
        d = fmax(d, rel_diff(got_state + 3, ref_state + 3, 3));             /* shear */
        for (i = 6; i < SUBFRIC_STATE_LEN; i++) d = fmax(d, rel_diff(got_state + i, ref_state + i, 1));
        d = fmax(d, rel_diff(&r.dshear_dslip[0][0], ref_tangent, 9));
        d = fmax(d, rel_diff(r.dshear_dpressure, ref_dp, 3));
        d = fmax(d, rel_diff(r.plastic_slip, ref_plastic_slip, 3));
        t.worst_ref = fmax(t.worst_ref, d);
        snprintf(detail, sizeof detail, "step %d: differs from the Rust path by %.3e", s, d);
        check(d <= REF_TOLERANCE && r.plastic == ref_plastic, name, detail);
        for (i = 0; i < 3; i++) traction[i] = next.shear[i] - p * normal[i] / sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        snprintf(detail, sizeof detail, "step %d: response.shear/traction", s);
        check(memcmp(r.shear, next.shear, sizeof r.shear) == 0 && rel_diff(r.traction, traction, 3) <= 1e-15, name, detail);

        /* In place, as on a state-variable array. */
        inplace = st;
        status = subfric_step(model, &inplace, dslip, p, dt, &inplace, NULL, NULL, 0);
        snprintf(detail, sizeof detail, "step %d: in-place step", s);
        check(status == SUBFRIC_STATUS_OK && memcmp(&inplace, &next, sizeof next) == 0, name, detail);

        /* Against finite differences. */
        du = sqrt(dslip[0] * dslip[0] + dslip[1] * dslip[1] + dslip[2] * dslip[2]);
        delta = du > 0.0 ? 0.005 * du : 1e-9;
        for (j = 0; j < 3 && ok; j++) {
            for (i = 0; i < 3; i++) e[i] = i == j ? 1.0 : 0.0;
            ok = fd4(model, &st, dslip, p, dt, e, delta, r.plastic, col);
            for (i = 0; i < 3; i++) fd[3 * i + j] = col[i];
        }
        ok = ok && fd4(model, &st, dslip, p, dt, NULL, 1e-3 * p, r.plastic, dp);
        if (ok) {
            double rel_p;
            err = 0.0;
            size = 0.0;
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) {
                    err += pow(r.dshear_dslip[i][j] - fd[3 * i + j], 2);
                    size += pow(r.dshear_dslip[i][j], 2);
                }
            err = sqrt(err / size);
            rel_p = r.plastic ? rel_diff(dp, r.dshear_dpressure, 3)
                              : sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]);
            t.worst_fd = fmax(t.worst_fd, err);
            t.worst_fd_p = fmax(t.worst_fd_p, rel_p);
            snprintf(detail, sizeof detail, "step %d: tangent vs finite differences %.3e, pressure %.3e", s, err, rel_p);
            check(err <= FD_TOLERANCE && rel_p <= FD_TOLERANCE, name, detail);
            if (r.plastic) t.plastic++; else t.elastic++;
        } else {
            t.skipped++;
        }
        t.steps++;
        st = next;
    }
    read_token(f, source, "end");
    printf("%-22s %4d steps (%d elastic, %d plastic, %d not differentiable), "
           "vs Rust %.1e, tangent vs FD %.2e, d/dp vs FD %.2e\n",
           name, t.steps, t.elastic, t.plastic, t.skipped, t.worst_ref, t.worst_fd, t.worst_fd_p);
    snprintf(kind, sizeof kind, "%d of %d steps could not be differentiated", t.skipped, t.steps);
    check(t.steps == nsteps && t.skipped == 0, name, kind);
    subfric_model_free(model);
}

static void check_errors(void) {
    char msg[MSG_LEN], small[8];
    SubfricParams prm = {0.45, 0.30, 1.2, 0.003, 15.0, 1000.0, 1000.0, NAN};
    SubfricModel *model = NULL;
    SubfricState st, st2;
    SubfricResponse r;
    SubfricStatus status;
    double du[3] = {0.01, 0.0, 0.0}, statev[SUBFRIC_STATE_LEN], zero[3] = {0.0, 0.0, 0.0};

    prm.mu_k = 0.9;
    prm.alpha_t = -1.0;
    status = subfric_model_new(&prm, NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_PARAMETERS && model == NULL && strstr(msg, "mu_k = 0.9") &&
              strstr(msg, "alpha_t = -1"),
          "invalid parameters are named:", msg);
    prm.mu_k = 0.30;
    prm.alpha_t = 1000.0;
    status = subfric_model_new(&prm, zero, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strstr(msg, "normal"), "a zero normal:", msg);
    status = subfric_model_new(NULL, NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_NULL_POINTER && strstr(msg, "params"), "NULL params:", msg);
    status = subfric_model_from_json("{\"mu_s\": 0.4,", NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_JSON && strstr(msg, "line 1"), "bad JSON:", msg);
    status = subfric_model_from_json("{\"model\": {\"params\": {\"mu_s\": 0.4}}}", NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_JSON && strstr(msg, "model.params.mu_k"), "missing key:", msg);
    status = subfric_model_from_json(
        "{\"params\": {\"mu_s\":0.45,\"mu_k\":0.3,\"kappa\":1.2,\"xi\":0.003,\"u_tilde\":15,\"alpha_t\":1},"
        " \"ext\": {\"rate\": {\"form\": \"log-direct\", \"a\": 0.01, \"v_c\": -1}}}",
        NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_PARAMETERS && strstr(msg, "rate.v_c"), "invalid extension:", msg);
    status = subfric_model_from_file("/nonexistent/fit.json", NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_IO && strstr(msg, "/nonexistent/fit.json"), "missing file:", msg);
    status = subfric_model_from_file("/dev/zero", NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_IO && strstr(msg, "not a regular file"), "a device as model file:", msg);
    status = subfric_model_new(&prm, NULL, zero, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && model == NULL && strstr(msg, "forward"), "a zero forward axis:", msg);
    {
        double along[3] = {0.0, 0.0, -2.0};
        status = subfric_model_new(&prm, NULL, along, &model, msg, MSG_LEN);
        check(status == SUBFRIC_STATUS_INVALID_INPUT && model == NULL && strstr(msg, "plane"),
              "a forward axis along the normal:", msg);
    }

    status = subfric_model_new(&prm, NULL, NULL, &model, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_OK, "base model:", msg);
    subfric_state_init(model, &st, NULL, 0);
    status = subfric_step(model, &st, du, -5.0, 1.0, &st2, &r, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strstr(msg, "pressure = -5"), "negative pressure:", msg);
    status = subfric_step(model, NULL, du, 100.0, 1.0, &st2, &r, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_NULL_POINTER && strstr(msg, "state_in"), "NULL state:", msg);
    du[1] = NAN;
    status = subfric_step(model, &st, du, 100.0, 1.0, &st2, &r, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strstr(msg, "dslip"), "NaN slip:", msg);
    du[1] = 0.0;
    status = subfric_step(model, &st, du, 100.0, 1.0, &st2, &r, small, sizeof small);
    check(status == SUBFRIC_STATUS_OK && small[0] == '\0', "success clears the message", NULL);
    status = subfric_step(model, &st, du, 100.0, -1.0, &st2, &r, small, sizeof small);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strlen(small) == sizeof small - 1 &&
              strncmp(small, "dt = -1", 7) == 0,
          "a short message buffer is truncated and terminated:", small);

    /* The state in a state-variable array (as Abaqus FRIC's STATEV), stepped in place. */
    memcpy(statev, &st, sizeof statev);
    status = subfric_step(model, (SubfricState *)statev, du, 100.0, 1.0, (SubfricState *)statev, NULL, msg, MSG_LEN);
    subfric_step(model, &st, du, 100.0, 1.0, &st2, NULL, NULL, 0);
    check(status == SUBFRIC_STATUS_OK && memcmp(statev, &st2, sizeof statev) == 0 &&
              sizeof(SubfricState) == SUBFRIC_STATE_LEN * sizeof(double),
          "state-variable array:", msg);

    /* A zero array is no state (README: a new contact point starts from subfric_state_init). */
    memset(statev, 0, sizeof statev);
    status = subfric_step(model, (SubfricState *)statev, du, 100.0, 1.0, &st2, &r, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strstr(msg, "subfric_state_init"), "an all-zero state:", msg);
    st2 = st;
    st2.mu = 100.0;
    status = subfric_step(model, &st2, du, 100.0, 1.0, &st2, &r, msg, MSG_LEN);
    check(status == SUBFRIC_STATUS_INVALID_INPUT && strstr(msg, "state.mu = 100") && st2.mu == 100.0,
          "mu beyond the model's bounds:", msg);

    /* Far from the origin: the same traction as near it, for elastic increments of 1e-8 mm. */
    {
        SubfricState near = st, far = st;
        SubfricResponse rn, rf;
        double tiny[3] = {1e-8, -2e-8, 0.0};
        int k, same = 1;
        far.slip[0] += 1e11;
        for (k = 0; k < 4; k++) {
            status = subfric_step(model, &near, k == 0 ? du : tiny, 100.0, 1.0, &near, &rn, msg, MSG_LEN);
            same = same && status == SUBFRIC_STATUS_OK;
            status = subfric_step(model, &far, k == 0 ? du : tiny, 100.0, 1.0, &far, &rf, msg, MSG_LEN);
            same = same && status == SUBFRIC_STATUS_OK && memcmp(rn.shear, rf.shear, sizeof rn.shear) == 0;
        }
        check(same && far.slip[0] > 1e10, "a slip record of 1e11 mm keeps the traction exact:", msg);
    }
    subfric_model_free(model);
    subfric_model_free(NULL);
    check(strlen(subfric_version()) > 0, "version", NULL);
}

int main(int argc, char **argv) {
    FILE *f;
    char word[256], name[256];
    if (argc != 2) {
        fprintf(stderr, "usage: %s CASES_FILE\n", argv[0]);
        return 2;
    }
    f = fopen(argv[1], "r");
    if (!f) {
        fprintf(stderr, "cannot open %s\n", argv[1]);
        return 2;
    }
    printf("subfric %s through the C interface\n", subfric_version());
    while (read_token(f, word, "case")) {
        read_token(f, name, NULL);
        run_case(f, name);
    }
    fclose(f);
    check_errors();
    printf("C checks: %d of %d passed\n", checks - failures, checks);
    return failures == 0 ? 0 : 1;
}
