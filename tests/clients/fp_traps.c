/* A meso code that traps floating-point exceptions (feenableexcept(FE_INVALID | FE_OVERFLOW |
 * FE_DIVBYZERO), as explicit codes do to stop at the first bad number) evaluates a block with points
 * refused outside the box (extrapolation=refuse) and invalid points (a negative pressure), in-process
 * and over gRPC (unary and stream=1). With fill=-1 it gets -1 where it would have got NaN; without
 * fill it gets NaN but mufric itself raises nothing on the way. Dying with SIGFPE fails the test.
 * Usage: fp_traps file:///path/gp.h5 MUFRIC_EXECUTABLE MODELS_DIR (which holds gp.h5) */
#define _GNU_SOURCE
#include <fenv.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "client/mufric.h"
#include "serve_helper.h"

enum { kPoints = 7 };
/* Inside seed 000's box (300-1300 MPa, 0.375-3.33 m/s, 298-1173 K) but for the marked inputs. */
static const double p[kPoints] = {800e6, 50e9 /* above */, -5e6 /* invalid */, 800e6, 900e6, 700e6, 800e6};
static const double v[kPoints] = {1.5, 1.5, 1.5, 1e-3 /* below */, 2.0, 1.0, 1.5};
static const double t[kPoints] = {600.0, 600.0, 600.0, 600.0, 700.0, 5000.0 /* above */, NAN /* invalid */};
static const int expected_status[kPoints] = {MUFRIC_POINT_OK,         MUFRIC_POINT_OUT_OF_BOX, MUFRIC_POINT_INVALID_INPUT,
                                             MUFRIC_POINT_OUT_OF_BOX, MUFRIC_POINT_OK,         MUFRIC_POINT_OUT_OF_BOX,
                                             MUFRIC_POINT_INVALID_INPUT};
/* mufric_evaluate_ex's flags: bit 2k below, 2k+1 above the box for input k; a NaN sets none. */
static const unsigned expected_outside[kPoints] = {0, 1u << 1, 1u << 0, 1u << 2, 0, 1u << 5, 0};

static int failures = 0;

static void check(int ok, const char* what, const char* where) {
  if (!ok) {
    fprintf(stderr, "FAILED (%s): %s\n", where, what);
    ++failures;
  }
}

/* One block through a handle opened with `options`; fill: the value expected for points without
 * an answer, or NaN for none (told apart with isnan, which is quiet). */
static void evaluate_block(const char* uri, const char* options, double fill, const char* where) {
  mufric_client* client = NULL;
  if (mufric_open_with_options(uri, options, &client) != MUFRIC_OK) {
    fprintf(stderr, "FAILED (%s): mufric_open: %s\n", where, mufric_last_error());
    ++failures;
    return;
  }
  double mu[kPoints], sd[kPoints], lo[kPoints], hi[kPoints];
  int status[kPoints];
  unsigned outside[kPoints];
  mufric_counts counts;
  for (int increment = 0; increment < 3; ++increment) {
    /* Every other increment through mufric_evaluate_ex, whose box flags compare the inputs too. */
    const int code = increment % 2 == 0
                         ? mufric_evaluate(client, kPoints, p, v, t, NULL, 0.95, mu, sd, lo, hi, status)
                         : mufric_evaluate_ex(client, kPoints, p, v, t, NULL, 0.95, mu, sd, lo, hi, status, outside,
                                              &counts);
    check(code == MUFRIC_PARTIAL, mufric_last_error(), where); /* five points without an answer */
    if (code != MUFRIC_PARTIAL) break;
    check(strncmp(mufric_last_error(), "point 1 OUT_OF_BOX: contact_pressure", 36) == 0,
          "the message names the first point without an answer", where);
    check(strstr(mufric_last_error(), "(and 4 more points without an answer)") != NULL, "and counts the others", where);
    if (increment % 2 == 1) {
      check(counts.out_of_box == 3 && counts.invalid == 2 && counts.extrapolated == 0, "counts", where);
      for (int i = 0; i < kPoints; ++i) check(outside[i] == expected_outside[i], "outside flags", where);
    }
    for (int i = 0; i < kPoints; ++i) {
      check(status[i] == expected_status[i], "status", where);
      const double outputs[4] = {mu[i], sd[i], lo[i], hi[i]};
      for (int k = 0; k < 4; ++k) {
        if (expected_status[i] == MUFRIC_POINT_OK) {
          check(isfinite(outputs[k]), "an answered point's outputs are finite", where);
        } else if (isnan(fill)) {
          check(isnan(outputs[k]), "without fill, a point without an answer gets NaN", where);
        } else {
          check(!isnan(outputs[k]) && outputs[k] == fill, "a point without an answer gets the fill value", where);
        }
      }
    }
    if (expected_status[0] == MUFRIC_POINT_OK) check(mu[0] > 0.0 && mu[0] < 1.0 && lo[0] <= mu[0] && mu[0] <= hi[0],
                                                     "the answered point's interval", where);
  }
  mufric_close(client);
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s file:///path/gp.h5 MUFRIC_EXECUTABLE MODELS_DIR\n", argv[0]);
    return 2;
  }
  char address[256];
  const pid_t server = serve_models(argv[2], argv[3], address, sizeof address);
  if (server < 0) return 1;
  char grpc_uri[320];
  snprintf(grpc_uri, sizeof grpc_uri, "grpc://%s/gp", address);

  /* From here on, a floating-point exception anywhere on this process's threads is SIGFPE. */
  feenableexcept(FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO);
  const char* uris[] = {argv[1], grpc_uri, grpc_uri};
  const char* transport_options[] = {"", "", "stream=1, "};
  const char* names[] = {"in-process", "gRPC unary", "gRPC stream"};
  for (int u = 0; u < 3; ++u) {
    char options[128], where[64];
    snprintf(options, sizeof options, "%sextrapolation=refuse, fill=-1", transport_options[u]);
    snprintf(where, sizeof where, "%s, fill=-1", names[u]);
    evaluate_block(uris[u], options, -1.0, where);
    snprintf(options, sizeof options, "%sextrapolation=refuse", transport_options[u]);
    snprintf(where, sizeof where, "%s, no fill", names[u]);
    evaluate_block(uris[u], options, NAN, where);
  }
  /* A bad fill is refused by name, and a NaN or infinite one too (it would defeat its purpose). */
  mufric_client* refused = NULL;
  const char* bad_fills[] = {"fill=nan", "fill=inf", "fill=-1x", "fill="};
  for (int k = 0; k < 4; ++k) {
    check(mufric_open_with_options(argv[1], bad_fills[k], &refused) == MUFRIC_INVALID_ARGUMENT && refused == NULL,
          bad_fills[k], "option refused");
    check(strstr(mufric_last_error(), "option fill") != NULL, mufric_last_error(), "the refusal names fill");
  }
  fedisableexcept(FE_ALL_EXCEPT);
  stop_server(server);
  if (failures == 0) printf("fp_traps: every check passed with FE_INVALID, FE_OVERFLOW and FE_DIVBYZERO trapping\n");
  return failures == 0 ? 0 : 1;
}
