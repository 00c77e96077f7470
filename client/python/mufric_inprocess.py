"""mufric in-process from Python: the C ABI of libmufric (mufric.h) through ctypes, numpy arrays in and
out, no server and no generated stubs. The same model, the same answers, options and statuses as a C
or Fortran meso code gets from mufric_open_with_options / mufric_evaluate_outputs.

    import numpy as np
    from mufric_inprocess import open_model
    with open_model("ti6al4v_tin", "fallback_mu=0.43") as model:     # a shipped name, a path or a URI
        a = model.evaluate(contact_pressure=np.array([9e8, 1.2e9]),    # SI: Pa, m/s, K (rad)
                           sliding_velocity=0.5, temperature=900.0)    # scalars are spread over the block
        a.mu, a.std, a.lo, a.hi, a.status, a.outside, a.counts, a.message

Where the library is: $MUFRIC_LIBRARY (a path to libmufric.so), else beside this file's install
(PREFIX/share/mufric/python -> PREFIX/lib/libmufric.so.0), else the loader's search path. grpc://
URIs work too (the C ABI's client), but a Python code with a server may rather use the stubs
(examples/python/evaluate_block.py).
"""
import ctypes
import ctypes.util
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# mufric.h's enums.
OK, INVALID_ARGUMENT, FAILED, PARTIAL = 0, 1, 2, 3
POINT_OK, POINT_EXTRAPOLATED, POINT_INVALID_INPUT, POINT_OUT_OF_BOX = 0, 1, 2, 3
POINT_STATUS_NAMES = {POINT_OK: "OK", POINT_EXTRAPOLATED: "EXTRAPOLATED", POINT_INVALID_INPUT: "INVALID_INPUT",
                      POINT_OUT_OF_BOX: "OUT_OF_BOX"}
# The C ABI's argument order of the inputs (mufric_box, the bits of `outside`).
INPUTS = ("contact_pressure", "sliding_velocity", "temperature", "fibre_angle")


class MufricError(RuntimeError):
    """A call that returned MUFRIC_FAILED or MUFRIC_INVALID_ARGUMENT, with mufric_last_error()'s words."""


class _Counts(ctypes.Structure):
    _fields_ = [("extrapolated", ctypes.c_size_t), ("invalid", ctypes.c_size_t), ("out_of_box", ctypes.c_size_t),
                ("range_clipped", ctypes.c_size_t), ("fast_points", ctypes.c_size_t)]


_double_p = ctypes.POINTER(ctypes.c_double)


class _Outputs(ctypes.Structure):
    _fields_ = [("mu", _double_p), ("std", _double_p), ("lo", _double_p), ("hi", _double_p),
                ("patch_std", _double_p), ("status", ctypes.POINTER(ctypes.c_int)),
                ("outside", ctypes.POINTER(ctypes.c_uint)), ("counts", ctypes.POINTER(_Counts))]


def _library_path():
    if os.environ.get("MUFRIC_LIBRARY"):
        return os.environ["MUFRIC_LIBRARY"]
    prefix = Path(__file__).resolve().parents[3]  # PREFIX/share/mufric/python/this file
    for installed in [prefix / "lib" / "libmufric.so.0", *sorted(prefix.glob("lib*/**/libmufric.so.0"))]:
        if installed.exists():
            return str(installed)
    found = ctypes.util.find_library("mufric")
    if not found:
        raise MufricError("libmufric not found: set MUFRIC_LIBRARY to its path (PREFIX/lib/libmufric.so.0, or "
                          "build/client/libmufric.so in a build tree)")
    return found


_lib = None


def _load():
    global _lib
    if _lib is not None:
        return _lib
    lib = ctypes.CDLL(_library_path())
    handle = ctypes.c_void_p
    lib.mufric_open_with_options.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(handle)]
    lib.mufric_open_with_options.restype = ctypes.c_int
    lib.mufric_close.argtypes = [handle]
    lib.mufric_close.restype = None
    lib.mufric_evaluate_outputs.argtypes = [handle, ctypes.c_size_t, _double_p, _double_p, _double_p, _double_p,
                                            ctypes.c_double, ctypes.POINTER(_Outputs)]
    lib.mufric_evaluate_outputs.restype = ctypes.c_int
    lib.mufric_box.argtypes = [handle, ctypes.POINTER(ctypes.c_int), _double_p, _double_p]
    lib.mufric_box.restype = ctypes.c_int
    lib.mufric_has_patch_scatter.argtypes = [handle]
    lib.mufric_has_patch_scatter.restype = ctypes.c_int
    lib.mufric_last_error.argtypes = []
    lib.mufric_last_error.restype = ctypes.c_char_p
    _lib = lib
    return lib


def _last_error(lib):
    return (lib.mufric_last_error() or b"").decode("utf-8", "replace")


@dataclass
class Answer:
    """One block's answer, SI; status per point (POINT_*), outside the box flags of mufric_evaluate_ex
    (bit 2k below, 2k+1 above for input k of INPUTS), the call's counts and code (OK or PARTIAL) and the
    message naming the first point without an answer ("" when all were answered)."""
    mu: np.ndarray
    std: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    status: np.ndarray
    outside: np.ndarray
    counts: dict
    code: int
    message: str
    patch_std: np.ndarray = field(default=None)

    def status_names(self):
        return [POINT_STATUS_NAMES.get(int(s), str(int(s))) for s in self.status]


class Model:
    """An open mufric handle (mufric_open_with_options). Close it, or use `with`."""

    def __init__(self, uri, options=""):
        self._lib = _load()
        self._handle = ctypes.c_void_p()
        rc = self._lib.mufric_open_with_options(str(uri).encode(), (options or "").encode(), ctypes.byref(self._handle))
        if rc != OK:
            raise MufricError(f"{uri}: {_last_error(self._lib)}")
        self.uri = uri

    def close(self):
        if self._handle:
            self._lib.mufric_close(self._handle)
            self._handle = ctypes.c_void_p()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may be gone
            pass

    def box(self):
        """{input name: (lo, hi)} in SI for the inputs the model takes."""
        used = (ctypes.c_int * 4)()
        lo, hi = (ctypes.c_double * 4)(), (ctypes.c_double * 4)()
        self._check(self._lib.mufric_box(self._handle, used, lo, hi), "box")
        return {INPUTS[k]: (lo[k], hi[k]) for k in range(4) if used[k]}

    def has_patch_scatter(self):
        return bool(self._lib.mufric_has_patch_scatter(self._handle))

    def evaluate(self, contact_pressure=None, sliding_velocity=None, temperature=None, fibre_angle=None,
                 level=0.95, patch_std=False):
        """μ, its std and `level` interval at n points (each input an array of n, or a scalar for all;
        None for an input the model does not take). A point without an answer does not raise: its status
        says which it is and the answer's message why (code PARTIAL)."""
        given = {"contact_pressure": contact_pressure, "sliding_velocity": sliding_velocity,
                 "temperature": temperature, "fibre_angle": fibre_angle}
        arrays = {k: np.atleast_1d(np.asarray(v, dtype=np.float64)) for k, v in given.items() if v is not None}
        for name, a in arrays.items():
            if a.ndim != 1:
                raise ValueError(f"{name}: a 1-D array or a scalar, not shape {a.shape}")
        lengths = {name: len(a) for name, a in arrays.items() if len(a) != 1}
        if len(set(lengths.values())) > 1:
            raise ValueError("the inputs differ in length: " + ", ".join(f"{k} {n}" for k, n in lengths.items()))
        n = next(iter(lengths.values()), 1 if arrays else 0)
        arrays = {k: np.ascontiguousarray(np.broadcast_to(a, n), dtype=np.float64) for k, a in arrays.items()}
        if not 0.0 < level < 1.0:
            raise ValueError(f"level: {level} is not in (0, 1)")
        out = {name: np.empty(n) for name in ("mu", "std", "lo", "hi")}
        status = np.empty(n, dtype=np.intc)
        outside = np.empty(n, dtype=np.uintc)
        counts = _Counts()
        outputs = _Outputs(*(o.ctypes.data_as(_double_p) for o in out.values()))
        scatter = np.empty(n) if patch_std else None
        if scatter is not None:
            outputs.patch_std = scatter.ctypes.data_as(_double_p)
        outputs.status = status.ctypes.data_as(ctypes.POINTER(ctypes.c_int))
        outputs.outside = outside.ctypes.data_as(ctypes.POINTER(ctypes.c_uint))
        outputs.counts = ctypes.pointer(counts)
        pointer = {k: (arrays[k].ctypes.data_as(_double_p) if k in arrays else None) for k in INPUTS}
        rc = self._lib.mufric_evaluate_outputs(self._handle, n, pointer["contact_pressure"], pointer["sliding_velocity"],
                                               pointer["temperature"], pointer["fibre_angle"], level,
                                               ctypes.byref(outputs))
        self._check(rc, "evaluate")
        return Answer(mu=out["mu"], std=out["std"], lo=out["lo"], hi=out["hi"], status=status, outside=outside,
                      counts={name: getattr(counts, name) for name, _ in _Counts._fields_}, code=rc,
                      message=_last_error(self._lib) if rc == PARTIAL else "", patch_std=scatter)

    def _check(self, rc, what):
        if rc in (OK, PARTIAL):
            return
        raise MufricError(f"{self.uri}: {what}: {_last_error(self._lib)}")


def open_model(uri, options=""):
    """A Model: uri is a shipped model's name, a path, file:///... or grpc://host:port/name; options as
    mufric_open_with_options takes them ("fallback_mu=0.43, extrapolation=refuse", ...)."""
    return Model(uri, options)
