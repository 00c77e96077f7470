#!/usr/bin/python3
"""Independent check of mufric's GP against scikit-learn (Debian python3-sklearn).

1. scikit-learn's log marginal likelihood at mufric's optimised hyper-parameters equals the LML
   mufric reports (same kernel C*RBF(ARD)+White, same unit-box inputs, same normalised outputs).
2. scikit-learn's predictive mean and std at those hyper-parameters equal `mufric predict`.
3. With the same bounds and number of starts, mufric's LML is at least scikit-learn's optimum.
Usage: sklearn_cross_check.py /path/to/mufric
"""
import re
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import h5py
import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

warnings.simplefilter("ignore", ConvergenceWarning)
MUFRIC = sys.argv[1]
RNG = np.random.default_rng(42)
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def field(p_mpa, v_m_min, t_c):
    ps, vs, ts = (p_mpa - 300) / 1000, (v_m_min - 22.5) / 177.5, (t_c - 25) / 875
    return 0.3 - 0.08 * ps + 0.05 * np.sin(3 * vs) + 0.1 * np.exp(-2 * ts) * (1 + 0.3 * ps * vs)


def kernel(s2, lengths, noise, bounded):
    if bounded:
        return (ConstantKernel(s2, (1e-3, 1e5)) * RBF(lengths, (1e-2, 1e3)) + WhiteKernel(noise, (1e-10, 1e-1)))
    return ConstantKernel(s2, "fixed") * RBF(lengths, "fixed") + WhiteKernel(noise, "fixed")


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    n = 150
    raw = np.column_stack([RNG.uniform(300, 1300, n), RNG.uniform(22.5, 200, n), RNG.uniform(25, 900, n)])
    mu = field(*raw.T) + RNG.normal(0, 1e-3, n)
    csv = tmp / "train.csv"
    with open(csv, "w") as out:
        out.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
        for row, m in zip(raw, mu):
            out.write(f"{row[0]!r},{row[1]!r},{row[2]!r},{m!r}\n")
    model = tmp / "model.h5"
    train = subprocess.run([MUFRIC, "train", "--data", str(csv), "--out", str(model), "--restarts", "2",
                            "--no-fast-evaluator"],  # the exact posterior against scikit-learn's
                           capture_output=True, text=True, check=True)
    with h5py.File(model, "r") as f:
        g = f["gp"]
        s2, noise, jitter = g.attrs["signal_variance"], g.attrs["noise_variance"], g.attrs["jitter"]
        lengths = g["length_scales"][:]
        lml_mufric = g["training"].attrs["log_marginal_likelihood"]
        lo, hi = f["inputs/box_lo"][:], f["inputs/box_hi"][:]

    # The CSV box is the data's range; mufric stores it in SI. Unit-box inputs for scikit-learn:
    si = np.column_stack([raw[:, 0] * 1e6, raw[:, 1] / 60, raw[:, 2] + 273.15])
    unit = (si - lo) / (hi - lo)
    fixed = GaussianProcessRegressor(kernel(s2, lengths, noise, False), optimizer=None, normalize_y=True,
                                     alpha=jitter).fit(unit, mu)
    lml_sklearn = fixed.log_marginal_likelihood_value_
    check(abs(lml_sklearn - lml_mufric) <= 1e-7 * abs(lml_mufric),
          f"LML at mufric's optimum: mufric {lml_mufric:.10f}, scikit-learn {lml_sklearn:.10f}")

    for k in range(5):
        q = np.array([RNG.uniform(300, 1300), RNG.uniform(22.5, 200), RNG.uniform(25, 900)])
        out = subprocess.run([MUFRIC, "predict", "--model", str(model), f"--p={q[0]!r}MPa", f"--v={q[1]!r}m/min",
                              f"--T={q[2]!r}C", "--extrapolation", "raw"],  # the GP itself, also just outside the data's box
                             capture_output=True, text=True, check=True).stdout
        m = re.search(r"mu = (\S+)\s+std (\S+)", out)
        q_unit = (np.array([q[0] * 1e6, q[1] / 60, q[2] + 273.15]) - lo) / (hi - lo)
        mean, std = fixed.predict(q_unit[None, :], return_std=True)
        check(abs(float(m.group(1)) - mean[0]) <= 1e-5 * abs(mean[0]) and
              abs(float(m.group(2)) - std[0]) <= 1e-2 * std[0],
              f"prediction {k}: mufric mu {m.group(1)} std {m.group(2)}, scikit-learn {mean[0]:.6g} {std[0]:.3g}")

    optimised = GaussianProcessRegressor(kernel(1.0, [0.5] * 3, 1e-5, True), n_restarts_optimizer=2,
                                         normalize_y=True, alpha=0.0, random_state=0).fit(unit, mu)
    best_sklearn = optimised.log_marginal_likelihood_value_
    check(lml_mufric >= best_sklearn - 1e-6 * abs(best_sklearn),
          f"optimum with 3 starts: mufric LML {lml_mufric:.6f} >= scikit-learn {best_sklearn:.6f}")

print(f"{5 + 2 - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
