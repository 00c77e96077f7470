/* What one mufric_evaluate call costs inside a meso code's time loop, not only in a tight loop.
 *
 *   call_cost_in_loop URI [points] [calls] [options]
 *
 * For each amount of "meso work" between two calls (0, 1, 20 and 50 ms), the loop does that work and
 * then asks for `points` contact points (default 10) with their 95 % interval, `calls` times (default
 * 200 at 0 ms, fewer with work so that each row takes ~4 s). The work streams through a 64 MB array
 * (read, add, write), as an explicit code's own field updates do: it evicts the caches mufric's data
 * lived in and leaves the process's other threads (OpenMP, gRPC) asleep, which a tight loop never
 * sees. Prints, per row, the median and the 90th percentile of the call's own wall time in µs.
 * options as mufric_open_with_options, e.g. "stream=1" for grpc://. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mufric/mufric.h>

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

enum { WORK_BYTES = 64 << 20 };

/* The meso code's own work: passes over a 64 MB field until `seconds` have gone by. */
static double meso_work(double* field, size_t n, double seconds) {
  const double until = now_s() + seconds;
  double sum = 0.0;
  while (seconds > 0.0 && now_s() < until) {
    for (size_t i = 0; i < n; i += 8) {
      field[i] += 1e-9;
      sum += field[i];
    }
  }
  return sum;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s URI [points] [calls] [options]\n", argv[0]);
    return 2;
  }
  const size_t points = argc > 2 ? (size_t)atol(argv[2]) : 10;
  const long tight_calls = argc > 3 ? atol(argv[3]) : 200;
  mufric_client* client = NULL;
  if (mufric_open_with_options(argv[1], argc > 4 ? argv[4] : "", &client) != MUFRIC_OK) {
    fprintf(stderr, "open: %s\n", mufric_last_error());
    return 1;
  }
  double *p = malloc(points * sizeof *p), *v = malloc(points * sizeof *v), *t = malloc(points * sizeof *t);
  double *mu = malloc(points * sizeof *mu), *lo = malloc(points * sizeof *lo), *hi = malloc(points * sizeof *hi);
  const size_t field_n = WORK_BYTES / sizeof(double);
  double* field = calloc(field_n, sizeof *field);
  for (size_t k = 0; k < points; ++k) {
    const double s = ((double)k + 0.5) / (double)points;
    p[k] = 320e6 + 850e6 * (1.0 - s);
    v[k] = 0.5 + 2.5 * s;
    t[k] = 473.15 + 600.0 * s;
  }
  const double work_ms[] = {0.0, 1.0, 20.0, 50.0};
  double checksum = 0.0;
  printf("%s, %zu points per call with the 95 %% interval%s%s\n", argv[1], points, argc > 4 ? ", options " : "",
         argc > 4 ? argv[4] : "");
  printf("| meso work between calls | calls | call p50 [us] | call p90 [us] |\n|---|---|---|---|\n");
  for (size_t w = 0; w < sizeof work_ms / sizeof work_ms[0]; ++w) {
    const long calls = work_ms[w] > 0.0 ? (long)(4000.0 / work_ms[w]) + 20 : tight_calls;
    double* seconds = malloc((size_t)calls * sizeof *seconds);
    for (long c = 0; c < calls; ++c) {
      checksum += meso_work(field, field_n, 1e-3 * work_ms[w]);
      for (size_t k = 0; k < points; ++k) p[k] *= 1.0 + 1e-6 * (double)((c + (long)k) % 3 - 1); /* the state moves */
      const double t0 = now_s();
      if (mufric_evaluate(client, points, p, v, t, NULL, 0.95, mu, NULL, lo, hi, NULL) != MUFRIC_OK) {
        fprintf(stderr, "evaluate: %s\n", mufric_last_error());
        return 1;
      }
      seconds[c] = now_s() - t0;
      checksum += mu[0];
    }
    qsort(seconds, (size_t)calls, sizeof *seconds, compare);
    printf("| %g ms | %ld | %.3g | %.3g |\n", work_ms[w], calls, 1e6 * seconds[calls / 2], 1e6 * seconds[calls * 9 / 10]);
    free(seconds);
  }
  fprintf(stderr, "(checksum %g)\n", checksum);
  mufric_close(client);
  return 0;
}
