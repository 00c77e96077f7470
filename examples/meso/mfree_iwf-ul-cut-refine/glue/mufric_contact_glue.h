/* mufric for a particle (SPH) contact algorithm: one call per time step for every particle in
 * contact with the tool, batched, in the contact code's own quantities (SI, plane strain, per metre
 * of depth). Part of the mfree_iwf-ul-cut-refine coupling; GPL-3.0-or-later like that code.
 *
 *   mufric_contact_glue* g;
 *   if (mufric_glue_open("file:///path/ti6al4v_tin.h5", "", 0.35, MUFRIC_GLUE_MEAN, &g) != 0) die(mufric_glue_error());
 *   each step:  mufric_glue_friction(g, n, fn, lc, vs, T, mu);    // mu[i] for particle i
 *   at the end: mufric_glue_close(g);
 *
 * What the glue decides (docs/usage.md, "What a meso code meets through the C ABI"):
 *  - contact pressure = the penalty normal force a particle receives over the contact length it
 *    stands for (its spacing): the micro-model's apparent pressure, not -sigma_nn from the bulk;
 *  - a point outside the model's box is answered by the model file's extrapolation policy (clamp:
 *    mu at the nearest point of the box) and counted per input and side;
 *  - a point without an answer (INVALID_INPUT, OUT_OF_BOX under extrapolation=refuse) gets the
 *    code's former constant mu (fallback_mu), never NaN (the code traps FE_INVALID);
 *  - MUFRIC_GLUE_LOWER / UPPER use the ends of the model's interval (ci_level) instead of its mean,
 *    for runs that show what the interval does to the forces;
 *  - mu is never negative (a friction force must oppose the slip).
 */
#ifndef MUFRIC_CONTACT_GLUE_H
#define MUFRIC_CONTACT_GLUE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mufric_contact_glue mufric_contact_glue;

enum mufric_glue_use { MUFRIC_GLUE_MEAN = 0, MUFRIC_GLUE_LOWER = 1, MUFRIC_GLUE_UPPER = 2 };

/* Counted over every call since open. outside[k][0/1]: points below/above the box in input k
 * (0 contact pressure, 1 sliding velocity, 2 temperature). */
typedef struct mufric_glue_counts {
  size_t calls;
  size_t points;
  size_t extrapolated;          /* outside the box, answered by the policy */
  size_t unanswered;            /* given fallback_mu */
  size_t outside[3][2];
  double seconds;               /* wall time inside mufric (the C ABI call and the glue's loops) */
} mufric_glue_counts;

/* uri and options as mufric_open_with_options (options may be NULL); fallback_mu in [0, 10];
 * ci_level in (0, 1) (used by LOWER/UPPER; 0.95 is the usual). Returns 0, or 1 with
 * mufric_glue_error() saying why. */
int mufric_glue_open(const char* uri, const char* options, double fallback_mu, int use, double ci_level,
                     mufric_contact_glue** glue);

/* n contact points: normal force per metre of depth [N/m] (its magnitude), contact length [m],
 * tangential slip speed against the tool [m/s], temperature [K]; mu[i] out. n = 0 is a no-op.
 * Returns 0 when every point was answered by the model (inside or outside the box), 2 when some got
 * fallback_mu (mufric_glue_error() names the first), 1 when the call failed (mu untouched). */
int mufric_glue_friction(mufric_contact_glue* glue, size_t n, const double* normal_force, const double* contact_length,
                         const double* slip_speed, const double* temperature, double* mu);

/* The same, from contact pressure [Pa] directly (what mufric_glue_friction computes first). */
int mufric_glue_friction_at(mufric_contact_glue* glue, size_t n, const double* contact_pressure,
                            const double* slip_speed, const double* temperature, double* mu);

/* The model's box (SI) in the order of mufric_glue_counts.outside. */
void mufric_glue_box(const mufric_contact_glue* glue, double lo[3], double hi[3]);

/* Every `every`-th call's points (p, v, T, mu, lo, hi, status) appended to a CSV at path, with a
 * unit header; every = 0 stops. For the plot of the meso code's contact states against the box. */
int mufric_glue_log_states(mufric_contact_glue* glue, const char* path, size_t every);

const mufric_glue_counts* mufric_glue_counts_so_far(const mufric_contact_glue* glue);
const char* mufric_glue_error(void);
void mufric_glue_close(mufric_contact_glue* glue);

#ifdef __cplusplus
}
#endif
#endif
