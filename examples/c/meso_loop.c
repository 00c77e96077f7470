/* A meso-side contact loop as an explicit chip-formation code writes it. Every increment, each
 * OpenMP thread gathers the contact points of its sub-domain of the rake face into one block, makes
 * one mufric_evaluate call on the handle all threads share, and uses the answer: the friction
 * traction tau = mu * p goes into the force, and a point whose 95 % interval is wide (half-width
 * above a fraction of mu) is flagged, as a meso code would log it for the next dataset campaign.
 *
 *   meso_loop URI [increments] [points_per_domain] [wide_fraction] [options]
 *
 * options as mufric_open_with_options, e.g. "stream=1" for grpc:// (one stream per increment loop).
 *
 * The contact field is synthetic (pressure falling, sliding speed and temperature rising along a
 * 0.2 mm contact length, breathing with the increment) and inside seed 000's box. The run is done
 * with one thread and again with two calling at once; it checks lo <= mu <= hi and status OK at
 * every point, and that both runs give the same force and flags to the last bit (each sub-domain's
 * block is the same whichever thread evaluates it). Exit 0 on success, 1 on a failed check. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mufric/mufric.h>

enum { DOMAINS = 2 };

static const double contact_length_m = 0.2e-3;

struct domain {
  size_t n;
  double *p, *v, *t, *mu, *lo, *hi;
  int* status;
  double force_n_per_m; /* friction force of this sub-domain, per unit width */
  long flagged;
  long bad;
};

/* The contact state of point k (of n) of a sub-domain at an increment. */
static void gather(struct domain* d, int domain_index, long increment) {
  const double breathing = 1.0 + 0.05 * sin(0.1 * (double)increment);
  for (size_t k = 0; k < d->n; ++k) {
    const double s = ((double)domain_index + ((double)k + 0.5) / (double)d->n) / DOMAINS; /* 0..1 along contact */
    d->p[k] = (320e6 + 850e6 * pow(1.0 - s, 1.5)) * breathing; /* Pa */
    d->v[k] = 0.5 + 2.5 * s;                                     /* m/s */
    d->t[k] = 473.15 + 600.0 * s * (1.0 - 0.4 * s);              /* K */
  }
}

/* One pass over all increments with `threads` threads; 0 on success. Prints ms per increment. */
static int run(mufric_client* client, struct domain* domains, long increments, double wide, int threads) {
  int failed = 0;
  const double start = omp_get_wtime();
  for (long increment = 0; increment < increments && !failed; ++increment) {
#pragma omp parallel for num_threads(threads) schedule(static, 1)
    for (int i = 0; i < DOMAINS; ++i) {
      struct domain* d = &domains[i];
      gather(d, i, increment);
      if (mufric_evaluate(client, d->n, d->p, d->v, d->t, NULL, 0.95, d->mu, NULL, d->lo, d->hi, d->status) !=
          MUFRIC_OK) {
#pragma omp critical
        {
          fprintf(stderr, "increment %ld, sub-domain %d: %s\n", increment, i, mufric_last_error());
          failed = 1;
        }
        continue;
      }
      const double dx = contact_length_m / DOMAINS / (double)d->n;
      double force = 0.0;
      for (size_t k = 0; k < d->n; ++k) {
        force += d->mu[k] * d->p[k] * dx;
        if (0.5 * (d->hi[k] - d->lo[k]) > wide * d->mu[k]) ++d->flagged;
        if (!(d->lo[k] <= d->mu[k] && d->mu[k] <= d->hi[k]) || d->status[k] != MUFRIC_POINT_OK) ++d->bad;
      }
      d->force_n_per_m += force;
    }
  }
  const double seconds = omp_get_wtime() - start;
  if (failed) return failed;
  printf("%d thread(s): %.3f ms per increment of %zu points\n", threads, 1e3 * seconds / (double)increments,
         DOMAINS * domains[0].n);
  return failed;
}

static void reset(struct domain* domains) {
  for (int i = 0; i < DOMAINS; ++i) {
    domains[i].force_n_per_m = 0.0;
    domains[i].flagged = 0;
    domains[i].bad = 0;
  }
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s URI [increments] [points_per_domain] [wide_fraction] [options]\n", argv[0]);
    return 2;
  }
  const long increments = argc > 2 ? atol(argv[2]) : 50;
  const size_t points = argc > 3 ? (size_t)atol(argv[3]) : 1000;
  const double wide = argc > 4 ? atof(argv[4]) : 0.05;
  if (increments < 1 || points < 1 || !(wide > 0.0)) {
    fprintf(stderr, "increments and points_per_domain must be >= 1, wide_fraction > 0\n");
    return 2;
  }
  mufric_client* client = NULL;
  if (mufric_open_with_options(argv[1], argc > 5 ? argv[5] : NULL, &client) != MUFRIC_OK) {
    fprintf(stderr, "%s\n", mufric_last_error());
    return 2;
  }
  struct domain domains[DOMAINS];
  for (int i = 0; i < DOMAINS; ++i) {
    struct domain* d = &domains[i];
    d->n = points;
    d->p = malloc(points * sizeof(double));
    d->v = malloc(points * sizeof(double));
    d->t = malloc(points * sizeof(double));
    d->mu = malloc(points * sizeof(double));
    d->lo = malloc(points * sizeof(double));
    d->hi = malloc(points * sizeof(double));
    d->status = malloc(points * sizeof(int));
  }

  double force[2];
  long flagged[2], bad[2];
  int failed = 0;
  for (int pass = 0; pass < 2 && !failed; ++pass) {
    reset(domains);
    failed = run(client, domains, increments, wide, pass + 1);
    force[pass] = domains[0].force_n_per_m + domains[1].force_n_per_m; /* fixed order: bitwise comparable */
    flagged[pass] = domains[0].flagged + domains[1].flagged;
    bad[pass] = domains[0].bad + domains[1].bad;
  }
  mufric_close(client);
  for (int i = 0; i < DOMAINS; ++i) {
    free(domains[i].p), free(domains[i].v), free(domains[i].t);
    free(domains[i].mu), free(domains[i].lo), free(domains[i].hi), free(domains[i].status);
  }
  if (failed) return 1;

  const double points_evaluated = (double)increments * DOMAINS * (double)points;
  printf("mean friction force %.6g N/m per increment; %ld of %.0f points flagged (95 %% half-width > %g mu)\n",
         force[0] / (double)increments, flagged[0], points_evaluated, wide);
  int failures = 0;
  if (bad[0] + bad[1] > 0) {
    fprintf(stderr, "%ld points outside their own interval or not OK\n", bad[0] + bad[1]);
    ++failures;
  }
  if (memcmp(&force[0], &force[1], sizeof(double)) != 0 || flagged[0] != flagged[1]) {
    fprintf(stderr, "two threads changed the answer: force %.17g vs %.17g, flagged %ld vs %ld\n", force[0], force[1],
            flagged[0], flagged[1]);
    ++failures;
  }
  if (!(force[0] > 0.0)) {
    fprintf(stderr, "no friction force\n");
    ++failures;
  }
  if (failures == 0) printf("one and two threads agree to the last bit\n");
  return failures ? 1 : 0;
}
