/* Test driver: reads points "p[Pa] v[m/s] T[K]" from stdin, evaluates them in one block through the
 * C ABI with std and a 95 % interval, prints "mu std lo hi status" per point in full precision.
 * The cross-language test compares these lines with an independent posterior. Usage: URI < points */
#include <stdio.h>
#include <stdlib.h>

#include "client/mufric.h"

enum { kMaxPoints = 1024 };

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s URI < points\n", argv[0]);
    return 2;
  }
  static double p[kMaxPoints], v[kMaxPoints], t[kMaxPoints], mu[kMaxPoints], sd[kMaxPoints], lo[kMaxPoints],
      hi[kMaxPoints];
  static int status[kMaxPoints];
  size_t n = 0;
  while (n < kMaxPoints && scanf("%lf %lf %lf", &p[n], &v[n], &t[n]) == 3) ++n;
  mufric_client* client = NULL;
  if (mufric_open(argv[1], &client) != MUFRIC_OK) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 1;
  }
  const int code = mufric_evaluate(client, n, p, v, t, NULL, 0.95, mu, sd, lo, hi, status);
  if (code != MUFRIC_OK && code != MUFRIC_PARTIAL) { /* PARTIAL: the statuses printed say which points */
    fprintf(stderr, "%s\n", mufric_last_error());
    return 1;
  }
  for (size_t i = 0; i < n; ++i) printf("%.17g %.17g %.17g %.17g %d\n", mu[i], sd[i], lo[i], hi[i], status[i]);
  mufric_close(client);
  return 0;
}
