/* A C meso code's view of mufric: open a model by URI, evaluate one block of contact points with a
 * 95 % interval and per-point status, handle errors by code and message. Checked here against the
 * closed-form seed-001 Table 4 law at 90 degrees.  Usage: evaluate_block URI */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <mufric/mufric.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s URI\n", argv[0]);
    return 2;
  }
  mufric_client* client = NULL;
  if (mufric_open(argv[1], &client) != MUFRIC_OK) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 2;
  }
  enum { n = 4 };
  const double p_mpa[n] = {50, 120, 180, NAN}, v_m_min[n] = {6, 10, 14, 5};
  double p[n], v[n], angle[n], mu[n], lo[n], hi[n];
  int status[n];
  for (int i = 0; i < n; ++i) {
    p[i] = p_mpa[i] * 1e6;
    v[i] = v_m_min[i] / 60.0;
    angle[i] = M_PI / 2;
  }
  int failures = 0;
  /* MUFRIC_PARTIAL: answered, but not every point (here the NaN pressure); status says which. */
  const int code = mufric_evaluate(client, n, p, v, NULL, angle, 0.95, mu, NULL, lo, hi, status);
  if (code != MUFRIC_OK && code != MUFRIC_PARTIAL) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 2;
  }
  if (code != MUFRIC_PARTIAL) ++failures;
  for (int i = 0; i < 3; ++i) {
    double expected = 0.149911 + 0.013133 * v_m_min[i] - 0.000753 * p_mpa[i];
    expected = fmin(fmax(expected, 0.093755565), 0.322395506);
    printf("p %6.1f MPa  v %5.1f m/min  mu %.6f  [%.6f, %.6f]  status %d\n", p_mpa[i], v_m_min[i], mu[i], lo[i], hi[i],
           status[i]);
    if (fabs(mu[i] - expected) > 1e-12 || status[i] != MUFRIC_POINT_OK) ++failures;
  }
  if (status[3] != MUFRIC_POINT_INVALID_INPUT || !isnan(mu[3])) ++failures; /* NaN pressure: that point only */
  /* A required input missing is an argument error with a message naming it. */
  if (mufric_evaluate(client, n, p, v, NULL, NULL, 0.0, mu, NULL, NULL, NULL, NULL) != MUFRIC_INVALID_ARGUMENT ||
      strstr(mufric_last_error(), "fibre_angle") == NULL) {
    ++failures;
  }
  mufric_close(client);
  /* An unknown model fails at open, with a message. */
  if (mufric_open("/nonexistent/model.h5", &client) != MUFRIC_FAILED || strstr(mufric_last_error(), "no such file") == NULL) {
    ++failures;
  }
  printf("%d passed, %d failed\n", failures == 0 ? 1 : 0, failures == 0 ? 0 : 1);
  return failures == 0 ? 0 : 1;
}
