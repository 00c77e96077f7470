/* The model's box through the C ABI (mufric_box), the per-input outside flags and the per-call
 * counts of mufric_evaluate_ex, in-process and over gRPC, each under the clamp and the refuse policy.
 * The box is checked against the one given on the command line (the fixture GP's, from its
 * `mufric describe`); the flags against the box itself for points just below and above each input;
 * the counts against a count of the statuses. Usage:
 *   box_and_counts file:///path/gp.h5 MUFRIC_EXECUTABLE MODELS_DIR P_LO P_HI V_LO V_HI T_LO T_HI */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "client/mufric.h"
#include "serve_helper.h"

enum { kInputs = 3, kMaxPoints = 32 };

static int failures = 0;

static void check(int ok, const char* what, const char* where) {
  if (!ok) {
    fprintf(stderr, "FAILED (%s): %s\n", where, what);
    ++failures;
  }
}

static void check_handle(const char* uri, const char* options, const double expected_lo[3],
                         const double expected_hi[3], const char* where) {
  mufric_client* client = NULL;
  if (mufric_open_with_options(uri, options, &client) != MUFRIC_OK) {
    fprintf(stderr, "FAILED (%s): mufric_open: %s\n", where, mufric_last_error());
    ++failures;
    return;
  }
  int used[4];
  double lo[4], hi[4];
  check(mufric_box(client, used, lo, hi) == MUFRIC_OK, "mufric_box", where);
  for (int k = 0; k < kInputs; ++k) {
    check(used[k] == 1, "the GP takes pressure, velocity and temperature", where);
    check(fabs(lo[k] - expected_lo[k]) <= 1e-9 * fabs(expected_lo[k]) &&
              fabs(hi[k] - expected_hi[k]) <= 1e-9 * fabs(expected_hi[k]),
          "the box is the model's (mufric describe)", where);
  }
  check(used[3] == 0 && lo[3] == 0.0 && hi[3] == 0.0, "no fibre angle: not used, box [0, 0]", where);
  check(mufric_box(client, NULL, lo, NULL) == MUFRIC_OK, "mufric_box takes NULL for what is not wanted", where);
  check(mufric_box(NULL, used, lo, hi) == MUFRIC_INVALID_ARGUMENT, "mufric_box of a NULL handle", where);

  /* Point 0 inside; then for each input one point just below and one just above its box; then two
   * inputs out at once, a negative pressure (invalid, and below the box), a NaN temperature (invalid,
   * no flag), and a point inside again. The fibre angle is sent but not a model input: no flags. */
  double x[kInputs][kMaxPoints], angle[kMaxPoints];
  unsigned expected_outside[kMaxPoints];
  size_t n = 0;
  for (size_t i = 0; i < kMaxPoints; ++i) {
    for (int k = 0; k < kInputs; ++k) x[k][i] = 0.5 * (lo[k] + hi[k]);
    angle[i] = 100.0;
    expected_outside[i] = 0;
  }
  n = 1;
  for (int k = 0; k < kInputs; ++k) {
    const double margin = 0.01 * (hi[k] - lo[k]);
    x[k][n] = lo[k] - margin;
    expected_outside[n++] = 1u << (2 * k);
    x[k][n] = hi[k] + margin;
    expected_outside[n++] = 1u << (2 * k + 1);
  }
  x[0][n] = 2.0 * hi[0];
  x[2][n] = 0.5 * lo[2];
  expected_outside[n++] = (1u << 1) | (1u << 4);
  x[0][n] = -5e6;
  expected_outside[n++] = 1u << 0;
  x[2][n] = NAN;
  expected_outside[n++] = 0;
  ++n;

  double mu[kMaxPoints], sd[kMaxPoints], cl[kMaxPoints], ch[kMaxPoints];
  int status[kMaxPoints];
  unsigned outside[kMaxPoints];
  mufric_counts counts;
  memset(&counts, 0xff, sizeof counts); /* every field must be written */
  const int code = mufric_evaluate_ex(client, n, x[0], x[1], x[2], angle, 0.95, mu, sd, cl, ch, status, outside, &counts);
  check(code == MUFRIC_PARTIAL, mufric_last_error(), where); /* two invalid points at least */
  size_t extrapolated = 0, invalid = 0, out_of_box = 0;
  for (size_t i = 0; i < n; ++i) {
    if (outside[i] != expected_outside[i]) {
      fprintf(stderr, "FAILED (%s): point %zu outside flags %#x, expected %#x\n", where, i, outside[i],
              expected_outside[i]);
      ++failures;
    }
    extrapolated += status[i] == MUFRIC_POINT_EXTRAPOLATED;
    invalid += status[i] == MUFRIC_POINT_INVALID_INPUT;
    out_of_box += status[i] == MUFRIC_POINT_OUT_OF_BOX;
  }
  const int refuse = strstr(options, "refuse") != NULL;
  check(invalid == 2, "a negative pressure and a NaN temperature are invalid", where);
  check((refuse ? out_of_box : extrapolated) == 7 && (refuse ? extrapolated : out_of_box) == 0,
        "the seven points outside the box are refused or extrapolated by the policy", where);
  check(counts.extrapolated == extrapolated && counts.invalid == invalid && counts.out_of_box == out_of_box,
        "counts match the statuses", where);
  check(counts.range_clipped <= n && counts.fast_points <= n, "range_clipped and fast_points are counts of points",
        where);
  /* The call answered the other points; its unanswered points are told about in mufric_last_error. */
  const char* expected_message = refuse ? "point 1 OUT_OF_BOX: contact_pressure" : "point 8 INVALID_INPUT: contact_pressure";
  check(strncmp(mufric_last_error(), expected_message, strlen(expected_message)) == 0, mufric_last_error(), where);

  /* Without the extras, mufric_evaluate answers the same; the inside points leave no message. */
  double mu_plain[kMaxPoints];
  check(mufric_evaluate(client, n, x[0], x[1], x[2], angle, 0.0, mu_plain, NULL, NULL, NULL, NULL) == MUFRIC_PARTIAL,
        mufric_last_error(), where);
  check(memcmp(mu_plain, mu, n * sizeof mu[0]) == 0, "mufric_evaluate gives the same mu", where);
  check(mufric_evaluate_ex(client, 1, x[0], x[1], x[2], NULL, 0.0, mu, NULL, NULL, NULL, NULL, outside, &counts) ==
                MUFRIC_OK &&
            mufric_last_error()[0] == '\0' && outside[0] == 0 && counts.extrapolated + counts.invalid +
                                                                         counts.out_of_box == 0,
        "an inside point: no flag, no count, no message", where);
  mufric_close(client);
}

int main(int argc, char** argv) {
  if (argc != 10) {
    fprintf(stderr, "usage: %s file:///path/gp.h5 MUFRIC_EXECUTABLE MODELS_DIR P_LO P_HI V_LO V_HI T_LO T_HI\n",
            argv[0]);
    return 2;
  }
  double expected_lo[3], expected_hi[3];
  for (int k = 0; k < 3; ++k) {
    expected_lo[k] = strtod(argv[4 + 2 * k], NULL);
    expected_hi[k] = strtod(argv[5 + 2 * k], NULL);
  }
  char address[256];
  const pid_t server = serve_models(argv[2], argv[3], address, sizeof address);
  if (server < 0) return 1;
  char grpc_uri[320];
  snprintf(grpc_uri, sizeof grpc_uri, "grpc://%s/gp", address);
  const char* policies[] = {"extrapolation=clamp", "extrapolation=refuse", "extrapolation=refuse, fill=-1"};
  for (int k = 0; k < 3; ++k) {
    char where[128];
    snprintf(where, sizeof where, "in-process, %s", policies[k]);
    check_handle(argv[1], policies[k], expected_lo, expected_hi, where);
    snprintf(where, sizeof where, "gRPC, %s", policies[k]);
    check_handle(grpc_uri, policies[k], expected_lo, expected_hi, where);
  }
  stop_server(server);
  if (failures == 0) printf("box_and_counts: every check passed\n");
  return failures == 0 ? 0 : 1;
}
