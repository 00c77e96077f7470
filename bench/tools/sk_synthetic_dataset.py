#!/usr/bin/env python3
"""A dataset of independent draws (schema 3) from a known heteroscedastic simulator, for benchmarks of
stochastic kriging at sizes the micro-model campaign has not reached: N samples of DRAWS draws each,
mu(x) = 0.2 + 0.05 sin(3 p*) cos(2 T*) and per-draw std 0.01 + 0.03 p* (p*, T* in [0, 1] over the box),
in the box and with the attributes of TEMPLATE (a campaign database).
  /usr/bin/python3 bench/tools/sk_synthetic_dataset.py TEMPLATE.h5 OUT.h5 N [DRAWS=4] [SEED=1]"""
import shutil
import sys

import h5py
import numpy as np

template, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
draws = int(sys.argv[4]) if len(sys.argv) > 4 else 4
rng = np.random.default_rng(int(sys.argv[5]) if len(sys.argv) > 5 else 1)
shutil.copyfile(template, out)
with h5py.File(out, "r+") as f:
    lo, hi = f["inputs/box_lo"][:], f["inputs/box_hi"][:]
    u = rng.random((n, 3))
    x = lo + u * (hi - lo)
    mean = 0.2 + 0.05 * np.sin(3 * u[:, 0]) * np.cos(2 * u[:, 2])
    spread = 0.01 + 0.03 * u[:, 0]
    draw_mu = mean[:, None] + spread[:, None] * rng.standard_normal((n, draws))
    del f["samples"]
    del f["plan"]
    f["plan/inputs"] = x
    f["plan"].attrs["design"] = "random"
    f["plan"].attrs["seed"] = 1
    f["plan"].attrs["draws"] = "independent"
    s = f.create_group("samples")
    s["inputs"] = x
    s["mu"] = draw_mu.mean(axis=1)
    s["mu_std"] = draw_mu.std(axis=1, ddof=1) / np.sqrt(draws)
    s["draw_mu"] = draw_mu
    s["status"] = np.zeros(n, dtype=np.int64)
    s["plan_index"] = np.arange(n, dtype=np.int64)
    s["tool_seed"] = np.arange(n, dtype=np.int64) * 2 + 10
    s["chip_seed"] = np.arange(n, dtype=np.int64) * 2 + 11
print(f"wrote {out}: {n} samples x {draws} draws")
