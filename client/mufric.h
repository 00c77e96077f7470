/* mufric C ABI: friction coefficients for meso-scale codes in C (and, through mufric.f90 and the
 * F77 entry points below, Fortran). Opaque handles, integer status codes, a per-thread last-error
 * message; no C++ exception crosses this interface. All quantities SI: Pa, m/s, K, rad.
 *
 *   mufric_client* c;
 *   if (mufric_open_with_options("grpc://127.0.0.1:50051/gp", "fallback_mu=0.35", &c) != MUFRIC_OK) {
 *     fprintf(stderr, "%s\n", mufric_last_error());
 *     exit(1);
 *   }
 *   int rc = mufric_evaluate(c, n, p, v, T, NULL, 0.95, mu, NULL, lo, hi, status);
 *   if (rc == MUFRIC_PARTIAL) {            // some points outside what the model answers:
 *     fprintf(stderr, "%s\n", mufric_last_error());  // their mu is 0.35, status[i] says which
 *   } else if (rc != MUFRIC_OK) {          // nothing answered: keep the previous mu, or stop
 *     fprintf(stderr, "%s\n", mufric_last_error());
 *   }
 *   mufric_close(c);
 *
 * Contact pressure from a particle (SPH) or node-to-surface code: send the normal traction the
 * contact algorithm applies to that particle, i.e. its contact force over the contact length (2D; the
 * area in 3D) it stands for, not -sigma_nn interpolated from the bulk at the particle. mu was learned
 * from the micro-model's apparent contact pressure, which is the applied normal load over the
 * apparent contact length, the same quantity; a kernel-smoothed -sigma_nn at a particle near a free
 * surface is deficient (its kernel sum is short of 1). Measured on a 2D SPH orthogonal cut of Ti6Al4V:
 * 95 % of its contact points inside dry_default's box with the penalty traction, 65 % with -sigma_nn.
 *
 * Threads: mufric_evaluate may be called on one handle from many threads at once (an OpenMP or
 * MPI + OpenMP meso code's contact loop); tested under ThreadSanitizer. A handle evaluating
 * in-process (file://) then answers each call on its calling thread: called inside an OpenMP
 * parallel region of two or more threads, or while another thread's call is running, it starts no
 * threads of its own.
 * Outside one it may use OMP_NUM_THREADS threads for a large block. Over grpc:// the calls run
 * concurrently. mufric_open and mufric_close must not race with calls on the same handle;
 * mufric_last_error is per thread.
 */
#ifndef MUFRIC_H
#define MUFRIC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mufric_client mufric_client;

enum mufric_status_code {
  MUFRIC_OK = 0,               /* every point answered (EXTRAPOLATED points included) */
  MUFRIC_INVALID_ARGUMENT = 1, /* null handle or array, bad level, an input the model needs is NULL */
  MUFRIC_FAILED = 2,           /* model not found, server unreachable, file unreadable: see mufric_last_error */
  MUFRIC_PARTIAL = 3           /* answered, but not every point: those with status INVALID_INPUT or OUT_OF_BOX
                                  have mu = fallback_mu=V (or fill=V, or NaN); mufric_last_error names the first */
};

/* EXTRAPOLATED: outside the model's training box, answered (raw or clamp policy); OUT_OF_BOX: outside
 * it under the refuse policy, NaN outputs (or the fill=V value). INVALID_INPUT: not a finite number or
 * physically impossible (a negative pressure, speed or temperature), NaN outputs (or V). */
enum mufric_point_status {
  MUFRIC_POINT_OK = 0,
  MUFRIC_POINT_EXTRAPOLATED = 1,
  MUFRIC_POINT_INVALID_INPUT = 2,
  MUFRIC_POINT_OUT_OF_BOX = 3
};

/* uri: "grpc://host:port/model", "file:///path/model.h5", a path, or the name of a model shipped with
   mufric ("dry_default": <prefix>/share/mufric/models/dry_default.h5, or $MUFRIC_MODELS_DIR). */
int mufric_open(const char* uri, mufric_client** client);

/* The same with options, "key=value" pairs separated by commas, semicolons or blanks (NULL or ""
 * for none); an unknown key or bad value is MUFRIC_INVALID_ARGUMENT naming it. For grpc(s)://:
 *   deadline=S        seconds per call (default 30)       retries=N    on UNAVAILABLE (default 4)
 *   backoff=S         first retry pause (default 0.05)    chunk_points=N, max_message_mb=N
 *   (chunk_points: most points per call, default 65536; from 128 up cut to a multiple of 128, so
 *   that a point's std has the same bits as in-process however a block is split)
 *   stream=1          every mufric_evaluate on one long-lived stream of this handle (an explicit
 *                     code's increments; no deadline). Measured (bench/studies/meso_calls/README.md, a 2-core AMD
 *                     EPYC node, client and server on it): 1.6x less time per call than unary
 *                     calls for ~11-point blocks (46 against 75 us), 49 against 73 us for one
 *                     point; no gain for blocks of thousands of points, where evaluation dominates
 *   token=T           bearer token (else $MUFRIC_TOKEN)
 *   tls_ca=F, tls_cert=F, tls_key=F   PEM files for grpcs:// (else $MUFRIC_TLS_CA, ...)
 *   mu_tolerance=E, std_tolerance=R   a model's certified fast evaluator answers (inside its box)
 *                     only if its measured bound is within these (defaults 1e-6 absolute on mu,
 *                     1e-3 relative on std); 0: the exact model for every point
 *   extrapolation=P   points outside the model's training box: raw (the model itself), clamp (mu of
 *                     the model at the nearest point of the box, with an interval that grows with the
 *                     distance from the box: the model's RMS error of that mu at the real point) or
 *                     refuse (OUT_OF_BOX, NaN); default:
 *                     the model file's policy (clamp unless it says otherwise)
 *   fill=V            points without an answer (INVALID_INPUT, OUT_OF_BOX) get the finite value V
 *                     in mu, std, lo and hi instead of NaN; their status still says which they
 *                     are. For codes that trap floating-point exceptions (see "Floating-point
 *                     traps" below). Not a mu to use: a negative V taken for mu reverses friction
 *   fallback_mu=V     mu of points without an answer (0 <= V <= 10, over fill): the value the code
 *                     would use there anyway, e.g. its former constant mu; the call still returns
 *                     MUFRIC_PARTIAL and their status says which they are
 *   log_uncertain=DIR file:// only: log the queries whose 95 % interval is wider than
 *                     uncertain_width=W (default 0.05) or that lie outside the box into
 *                     DIR/<model file's stem>.csv (and .outside.json), as `mufric serve
 *                     --log-uncertain DIR` does, for `mufric learn`; log_every=N logs every N-th
 *                     call only (each logged call computes the std); uncertain_max_rows=R as the server's
 * e.g. mufric_open_with_options("grpc://node7:50051/gp", "stream=1, deadline=2", &c). */
int mufric_open_with_options(const char* uri, const char* options, mufric_client** client);
void mufric_close(mufric_client* client);

/* n points. Inputs: NULL for inputs not sent (the model's own inputs are required). Outputs: NULL
 * for outputs not wanted; lo/hi need ci_level in (0, 1), else pass 0. status: one
 * mufric_point_status per point, or NULL. n = 0 (a step without contact) is a no-op that returns
 * MUFRIC_OK whatever the arrays. Points without an answer (INVALID_INPUT, OUT_OF_BOX) get mu =
 * fallback_mu=V if the handle has one, else the fill=V value, else NaN (std, lo, hi: fill or NaN);
 * the others are answered, and the call returns MUFRIC_PARTIAL, with the first such point, the input
 * and why in mufric_last_error(). MUFRIC_OK: every point was answered.
 *
 * Floating-point traps: a code that enables feenableexcept(FE_INVALID | FE_OVERFLOW | ...) must open
 * its handle with fill=V, or be handed NaN (which it will trap on at its first comparison). With V,
 * mufric's own code on the calling thread raises no FE_INVALID for such points either: they are told
 * apart by their status and the box flags below by quiet comparisons (isless/isgreater), never by
 * an ordered comparison with a NaN. Tested in-process and over gRPC with FE_INVALID, FE_OVERFLOW and
 * FE_DIVBYZERO trapping (tests/clients/fp_traps.c). */
int mufric_evaluate(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                    const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                    double* lo, double* hi, int* status);

/* What one mufric_evaluate_ex call met, counted over its n points. */
typedef struct mufric_counts {
  size_t extrapolated;  /* MUFRIC_POINT_EXTRAPOLATED: outside the box, answered (raw or clamp) */
  size_t invalid;       /* MUFRIC_POINT_INVALID_INPUT */
  size_t out_of_box;    /* MUFRIC_POINT_OUT_OF_BOX (extrapolation=refuse) */
  size_t range_clipped; /* mu or its interval clipped to the model's physical range of mu */
  size_t fast_points;   /* answered by the model's certified fast evaluator; the rest by the exact model */
} mufric_counts;

/* mufric_evaluate with two more outputs, each NULL if not wanted:
 *   outside  n values; for input k in argument order (0 contact_pressure, 1 sliding_velocity,
 *            2 temperature, 3 fibre_angle) bit 2k is set when the point's input lies below the model's
 *            training box (mufric_box), bit 2k+1 when above; 0 for a point inside and for inputs the
 *            model does not take. Outside as the model sees it: a fibre angle a half turn (180
 *            degrees) away from a point of the box is inside. Set whatever the point's status (a
 *            negative pressure is below the box too); a NaN input sets no bit.
 *   counts   one struct, this call's counts.
 * As for mufric_evaluate, a call with points without an answer returns MUFRIC_PARTIAL and leaves
 * its message in mufric_last_error() ("" when every point was answered). */
int mufric_evaluate_ex(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                       const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                       double* lo, double* hi, int* status, unsigned* outside, mufric_counts* counts);

/* Every output of one evaluation, each NULL if not wanted (mu included), for mufric_evaluate_outputs. */
typedef struct mufric_outputs {
  double* mu;
  double* std;         /* the standard deviation of mu */
  double* lo;          /* the ci_level interval of mu; lo and hi need ci_level in (0, 1) */
  double* hi;
  double* patch_std;   /* the patch scatter (mufric_patch_std); only from a model that has one */
  int* status;         /* mufric_point_status */
  unsigned* outside;   /* the box flags of mufric_evaluate_ex */
  mufric_counts* counts;
} mufric_outputs;

/* Everything in one call: mu, its interval and the patch scatter come from one evaluation (a meso
 * code that wants both pays for one call, not two). Same inputs and return codes as mufric_evaluate;
 * outputs NULL is MUFRIC_INVALID_ARGUMENT; an outputs struct zero-initialised but for what is wanted:
 *   mufric_outputs out = {0};  out.mu = mu;  out.patch_std = scatter;  out.status = status;
 *   rc = mufric_evaluate_outputs(c, n, p, v, T, NULL, 0.0, &out); */
int mufric_evaluate_outputs(mufric_client* client, size_t n, const double* contact_pressure,
                            const double* sliding_velocity, const double* temperature, const double* fibre_angle,
                            double ci_level, const mufric_outputs* outputs);

/* The model's training box, in the argument order of mufric_evaluate (contact_pressure,
 * sliding_velocity, temperature, fibre_angle), SI: used[k] = 1 and lo[k] <= hi[k] for an input the
 * model takes, used[k] = 0 and lo[k] = hi[k] = 0 for one it does not. Any of the three may be NULL.
 * Read when the handle was opened (no call to the server). */
int mufric_box(mufric_client* client, int used[4], double lo[4], double hi[4]);

/* The patch scatter (issue 33): at each of n points, how much one contact patch's mu scatters about
 * the mean mufric_evaluate serves there (the micro-model's per-draw standard deviation), for a meso
 * code that wants a spatially varying mu along the rake face; never part of std or the interval.
 * Same inputs and return codes as mufric_evaluate; a point without an answer gets NaN or the fill=V
 * value, and its status (if status is not NULL). MUFRIC_INVALID_ARGUMENT when the model has none (one trained on common
 * draws, or not a GP): mufric_has_patch_scatter says so beforehand. */
int mufric_patch_std(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                     const double* temperature, const double* fibre_angle, double* patch_std, int* status);
/* 1 when the model serves mufric_patch_std, 0 when not (or client is NULL). */
int mufric_has_patch_scatter(mufric_client* client);

/* The message of the last failure on this thread, or of the last evaluation's points without an
 * answer ("" if none). Valid until the next call. */
const char* mufric_last_error(void);

/* F77-style entry points (trailing underscore, every argument by reference, hidden string length
 * last) for Fortran callers without modules, e.g. an Abaqus VFRICTION routine:
 *   integer*8 handle; integer status
 *   call mufric_open('file:///path/law.h5', handle, status)
 *   call mufric_evaluate(handle, n, p, v, t, angle, mu, status)   ! all four input arrays, length n
 *   call mufric_close(handle) */
void mufric_open_(const char* uri, int64_t* handle, int32_t* status, size_t uri_length);
/*   call mufric_open_with_options('grpc://node7:50051/gp', 'stream=1', handle, status) */
void mufric_open_with_options_(const char* uri, const char* options, int64_t* handle, int32_t* status,
                               size_t uri_length, size_t options_length);
void mufric_evaluate_(const int64_t* handle, const int32_t* n, const double* contact_pressure,
                      const double* sliding_velocity, const double* temperature, const double* fibre_angle, double* mu,
                      int32_t* status);
void mufric_close_(const int64_t* handle);

#ifdef __cplusplus
}
#endif

#endif /* MUFRIC_H */
