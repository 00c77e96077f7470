/* mufric C ABI: friction coefficients for meso-scale codes in C (and, through mufric.f90 and the
 * F77 entry points below, Fortran). Opaque handles, integer status codes, a per-thread last-error
 * message; no C++ exception crosses this interface. All quantities SI: Pa, m/s, K, rad.
 *
 *   mufric_client* c;
 *   if (mufric_open("grpc://127.0.0.1:50051/gp", &c) != MUFRIC_OK) puts(mufric_last_error());
 *   mufric_evaluate(c, n, p, v, T, NULL, 0.95, mu, NULL, lo, hi, status);
 *   mufric_close(c);
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
  MUFRIC_OK = 0,
  MUFRIC_INVALID_ARGUMENT = 1, /* null handle or array, bad level, an input the model needs is NULL */
  MUFRIC_FAILED = 2            /* model not found, server unreachable, file unreadable: see mufric_last_error */
};

/* EXTRAPOLATED: outside the model's training box, answered (raw or clamp policy); OUT_OF_BOX: outside
 * it under the refuse policy, NaN outputs. */
enum mufric_point_status {
  MUFRIC_POINT_OK = 0,
  MUFRIC_POINT_EXTRAPOLATED = 1,
  MUFRIC_POINT_INVALID_INPUT = 2,
  MUFRIC_POINT_OUT_OF_BOX = 3
};

/* uri: "grpc://host:port/model", "file:///path/model.h5" or a path. */
int mufric_open(const char* uri, mufric_client** client);

/* The same with options, "key=value" pairs separated by commas, semicolons or blanks (NULL or ""
 * for none); an unknown key or bad value is MUFRIC_INVALID_ARGUMENT naming it. For grpc(s)://:
 *   deadline=S        seconds per call (default 30)       retries=N    on UNAVAILABLE (default 4)
 *   backoff=S         first retry pause (default 0.05)    chunk_points=N, max_message_mb=N
 *   (chunk_points: most points per call, default 65536; from 128 up cut to a multiple of 128, so
 *   that a point's std has the same bits as in-process however a block is split)
 *   stream=1          every mufric_evaluate on one long-lived stream of this handle (an explicit
 *                     code's increments: ~5x less overhead per call than unary calls; no deadline)
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
 * e.g. mufric_open_with_options("grpc://node7:50051/gp", "stream=1, deadline=2", &c). */
int mufric_open_with_options(const char* uri, const char* options, mufric_client** client);
void mufric_close(mufric_client* client);

/* n points. Inputs: NULL for inputs not sent (the model's own inputs are required). Outputs: NULL
 * for outputs not wanted; lo/hi need ci_level in (0, 1), else pass 0. status: one
 * mufric_point_status per point, or NULL. Invalid points get NaN outputs; the others are answered. */
int mufric_evaluate(mufric_client* client, size_t n, const double* contact_pressure, const double* sliding_velocity,
                    const double* temperature, const double* fibre_angle, double ci_level, double* mu, double* std,
                    double* lo, double* hi, int* status);

/* The message of the last failure on this thread ("" if none). Valid until the next call. */
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
