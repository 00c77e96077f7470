#!/usr/bin/python3
"""Every client language end to end on loopback against a running `mufric serve`:

1. Python (generated stubs, examples/python/evaluate_block.py): mu of a seed-001 law against the
   closed-form Table 4 law; NOT_FOUND for an unknown model, INVALID_ARGUMENT for unequal arrays.
2. A Gaussian process trained by `mufric train`: mu, std and the 95 % interval from Python over gRPC,
   from C (the C ABI over grpc:// and file://) and from Fortran (the ISO_C_BINDING module over
   grpc://), each against an independent posterior computed here with numpy from the model file's
   hyper-parameters and training data (Rasmussen & Williams 2006, Algorithm 2.1).
3. The C example program over grpc:// against the law.
4. The VFRICTION-style Fortran example (F77 entry points) over grpc:// against the law.
Usage: python_client_test.py --mufric EXE --stubs DIR --examples DIR --c-example EXE --c-driver EXE
                             [--fortran-driver EXE] [--vfriction EXE]"""
import argparse
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
for name in ("mufric", "stubs", "examples", "c-example", "c-driver"):
    parser.add_argument("--" + name, required=True)
parser.add_argument("--fortran-driver")
parser.add_argument("--vfriction")
parser.add_argument("--library", help="libmufric.so, for the Python in-process module (client/python)")
parser.add_argument("--inprocess-module", help="the folder of mufric_inprocess.py")
args = parser.parse_args()
mufric, c_example, c_driver, fortran_driver = args.mufric, args.c_example, args.c_driver, args.fortran_driver
sys.path[:0] = [args.stubs, args.examples]
from statistics import NormalDist  # noqa: E402

import grpc  # noqa: E402
import h5py  # noqa: E402
import numpy as np  # noqa: E402
from mufric.v1 import friction_pb2, friction_pb2_grpc  # noqa: E402
import evaluate_block  # noqa: E402
import mufric_channel  # noqa: E402

failures = []


checks = 0
# The server's and numpy's posteriors differ only by rounding in different operation orders.
POSTERIOR_RTOL = 1e-9


def check(ok, what):
    global checks
    checks += 1
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def reference_posterior(model_path, x):
    """mu, std of the GP in model_path at SI points x (m x 3), computed independently with numpy."""
    with h5py.File(model_path, "r") as f:
        g = f["gp"]
        lo, hi = f["inputs/box_lo"][()], f["inputs/box_hi"][()]
        scale = lambda a: (a - lo) / (hi - lo)  # noqa: E731
        xs, y = scale(g["x_train"][()]), g["y_train"][()]
        s2, noise, jitter = g.attrs["signal_variance"], g.attrs["noise_variance"], g.attrs["jitter"]
        lengths, y_mean, y_scale = g["length_scales"][()], g.attrs["y_mean"], g.attrs["y_scale"]
        if not g.attrs["noise_term"]:
            noise = 0.0

    def rbf(a, b):
        d = (a[:, None, :] - b[None, :, :]) / lengths
        return s2 * np.exp(-0.5 * np.sum(d * d, axis=2))

    k = rbf(xs, xs) + (noise + jitter) * np.eye(len(xs))
    ks = rbf(scale(x), xs)
    mean = ks @ np.linalg.solve(k, (y - y_mean) / y_scale)
    var = s2 + noise - np.einsum("ij,ji->i", ks, np.linalg.solve(k, ks.T))
    return y_mean + y_scale * mean, y_scale * np.sqrt(var)


def close(a, b):
    return np.allclose(a, b, rtol=POSTERIOR_RTOL, atol=POSTERIOR_RTOL * np.max(np.abs(b)))


def check_gp_answer(who, mu, std, lo, hi, ref_mu, ref_std):
    z = NormalDist().inv_cdf(0.975)
    check(close(mu, ref_mu), f"{who}: mu equals the numpy posterior mean (max diff {np.max(np.abs(mu - ref_mu)):.1e})")
    check(close(std, ref_std), f"{who}: std equals the numpy posterior std (max diff {np.max(np.abs(std - ref_std)):.1e})")
    check(close(lo, ref_mu - z * ref_std) and close(hi, ref_mu + z * ref_std), f"{who}: 95 % interval = mu -+ 1.96 std")


def run_driver(driver, uri, x, count_first):
    text = (f"{len(x)}\n" if count_first else "") + "".join(f"{p!r} {v!r} {t!r}\n" for p, v, t in x)
    out = subprocess.run([driver, uri], input=text, capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        return None, out.stderr
    rows = np.array([[float(w) for w in line.split()] for line in out.stdout.splitlines() if line.strip()])
    return rows, ""


def check_example_command_line(address):
    """evaluate_block.py as a user runs it: points on its command line with units, one-line errors."""
    example = [sys.executable, str(Path(args.examples) / "evaluate_block.py")]
    env = {**os.environ, "PYTHONPATH": args.stubs}
    run = lambda *a: subprocess.run(example + list(a), capture_output=True, text=True, timeout=60, env=env)  # noqa: E731
    ok = run(address, "law", "--p", "50MPa", "0.12GPa", "--v", "10m/min", "--angle", "90deg")
    answers = [line for line in ok.stdout.splitlines() if " mu " in line]
    check(ok.returncode == 0 and len(answers) == 2 and "contact_pressure 120 MPa" in answers[1],
          f"evaluate_block.py --p 50MPa 0.12GPa --v 10m/min: two points answered\n{ok.stdout}{ok.stderr}")
    bad = run(address, "law", "--p", "800", "--v", "10m/min")
    check(bad.returncode != 0 and "--p '800': give a number with a unit" in bad.stderr and "Traceback" not in bad.stderr,
          f"a bare number refused in one line: {bad.stderr.strip()}")
    missing = run(address, "no_such_model", "--timeout", "5")
    check(missing.returncode == 2 and missing.stderr.count("\n") == 1 and "NOT_FOUND" in missing.stderr,
          f"an unknown model: one line, NOT_FOUND: {missing.stderr.strip()}")
    nobody = run("127.0.0.1:1", "--timeout", "0.5")
    check(nobody.returncode == 2 and "no mufric server answered at 127.0.0.1:1" in nobody.stderr and "Traceback" not in nobody.stderr,
          f"no server: one line: {nobody.stderr.strip()}")


def check_python_in_process(tmp, queries, ref_mu, ref_std):
    """client/python/mufric_inprocess.py: the C ABI through ctypes, no server (issue 72)."""
    os.environ["MUFRIC_LIBRARY"] = args.library
    sys.path.insert(0, args.inprocess_module)
    import mufric_inprocess as mf
    with mf.open_model(f"file://{tmp}/models/gp.h5", "fallback_mu=0.3") as model:
        a = model.evaluate(contact_pressure=queries[:, 0], sliding_velocity=queries[:, 1], temperature=queries[:, 2])
        check_gp_answer("Python in-process", a.mu, a.std, a.lo, a.hi, ref_mu, ref_std)
        check(a.code == mf.OK and np.all(a.status == mf.POINT_OK) and a.message == "", "Python in-process: every point OK")
        box = model.box()
        check(sorted(box) == ["contact_pressure", "sliding_velocity", "temperature"], f"the box's inputs ({sorted(box)})")
        p_hi = box["contact_pressure"][1]
        # scalars spread over the block; one point above the pressure box, one invalid
        b = model.evaluate(contact_pressure=np.array([0.5 * p_hi, 2 * p_hi, -5e6]), sliding_velocity=1.0, temperature=600.0)
        check(b.status_names() == ["OK", "EXTRAPOLATED", "INVALID_INPUT"], f"statuses ({b.status_names()})")
        check(b.code == mf.PARTIAL and "point 2 INVALID_INPUT: contact_pressure" in b.message, f"PARTIAL, why: {b.message!r}")
        check(b.mu[2] == 0.3 and b.outside[1] == 2 and b.outside[0] == 0, "fallback mu; bit 1: pressure above the box")
        check(b.counts["extrapolated"] == 1 and b.counts["invalid"] == 1, f"counts {b.counts}")
        try:
            model.evaluate(contact_pressure=[1e8, 2e8], sliding_velocity=[1.0, 2.0, 3.0], temperature=600.0)
            check(False, "unequal arrays refused")
        except ValueError as e:
            check("contact_pressure 2, sliding_velocity 3" in str(e), f"unequal arrays named: {e}")
        empty = model.evaluate(contact_pressure=[], sliding_velocity=[], temperature=[])
        check(empty.code == mf.OK and len(empty.mu) == 0, "an empty block: no-op")
    try:
        mf.open_model(f"file://{tmp}/models/none.h5")
        check(False, "a missing model file refused")
    except mf.MufricError as e:
        check("none.h5" in str(e), f"a missing model named: {e}")
    try:
        mf.open_model(f"file://{tmp}/models/gp.h5", "fallback=1")
        check(False, "an unknown option refused")
    except mf.MufricError as e:
        check("fallback" in str(e), f"an unknown option named: {e}")


def make_gp(tmp):
    """A GP trained by mufric on 80 noisy samples of a smooth field over the seed-000 box."""
    rng = np.random.default_rng(7)
    raw = np.column_stack([rng.uniform(300, 1300, 80), rng.uniform(22.5, 200, 80), rng.uniform(25, 900, 80)])
    mu = 0.3 - 0.08 * (raw[:, 0] - 300) / 1000 + 0.05 * np.sin(3 * (raw[:, 1] - 22.5) / 177.5) \
        + 0.1 * np.exp(-2 * (raw[:, 2] - 25) / 875) + rng.normal(0, 2e-3, 80)
    with open(tmp / "train.csv", "w") as out:
        out.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
        for row, m in zip(raw, mu):
            out.write(f"{row[0]!r},{row[1]!r},{row[2]!r},{m!r}\n")
    # The exact posterior, checked to round-off through every binding: no fast evaluator here (its
    # own bound is tested in C++, FastEvaluator.*).
    subprocess.run([mufric, "train", "--data", str(tmp / "train.csv"), "--out", str(tmp / "models/gp.h5"),
                    "--restarts", "1", "--no-fast-evaluator"], check=True, capture_output=True)
    # SI query points inside the box.
    q = np.column_stack([rng.uniform(500e6, 1100e6, 12), rng.uniform(0.8, 2.8, 12), rng.uniform(400, 1000, 12)])
    return q


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    (tmp / "models").mkdir()
    subprocess.run([mufric, "law", "seward", "--table", "4", "--out", str(tmp / "models/law.h5")], check=True,
                   capture_output=True)
    queries = make_gp(tmp)
    ref_mu, ref_std = reference_posterior(tmp / "models/gp.h5", queries)
    server = subprocess.Popen([mufric, "serve", "--models", str(tmp / "models"), "--listen", "127.0.0.1:0",
                               "--ready-file", str(tmp / "address")], stderr=subprocess.DEVNULL)
    try:
        for _ in range(100):
            if (tmp / "address").exists() and (tmp / "address").read_text().strip():
                break
            time.sleep(0.05)
        address = (tmp / "address").read_text().strip()
        points = {"contact_pressure": [50e6, 120e6, 180e6], "sliding_velocity": [0.1, 10.0 / 60.0, 14.0 / 60.0],
                  "fibre_angle": [math.pi / 2] * 3}
        answer = evaluate_block.main(address, "law", points)
        for mu, p, v in zip(answer.mu, [50.0, 120.0, 180.0], [6.0, 10.0, 14.0]):
            expected = min(max(0.149911 + 0.013133 * v - 0.000753 * p, 0.093755565), 0.322395506)
            check(abs(mu - expected) < 1e-12, f"mu at {p} MPa, {v} m/min = {mu:.9f} (closed form {expected:.9f})")
        # Without points, the example asks at the law's own inputs (no temperature: the law has none).
        spread = evaluate_block.main(address, "law")
        check(len(spread.mu) == 3 and list(spread.ignored_inputs) == [], "the example reads the law's inputs from DescribeModel")
        stub = friction_pb2_grpc.FrictionServiceStub(grpc.insecure_channel(address))
        with_temperature = stub.Evaluate(friction_pb2.EvaluateRequest(model="law", temperature=[293.15] * 3, **points), timeout=10)
        check(list(with_temperature.ignored_inputs) == ["temperature"], "temperature reported as ignored by the law")
        # A refusal with the server's retry hint is retried after it; any other error is raised.
        calls, pauses = [], []

        class Refused(grpc.RpcError):
            def code(self):
                return grpc.StatusCode.RESOURCE_EXHAUSTED

            def trailing_metadata(self):
                return (("mufric-retry-after-ms", "250"),)

        def busy_then_ok(request, timeout, wait_for_ready):
            calls.append(request)
            if len(calls) < 3:
                raise Refused()
            return "answered"

        result = mufric_channel.call_with_retry(busy_then_ok, "request", timeout=1, sleep=pauses.append)
        check(result == "answered" and len(calls) == 3 and pauses == [0.25, 0.25],
              f"call_with_retry: waited the hint twice, then answered ({len(calls)} calls, pauses {pauses})")
        stub = friction_pb2_grpc.FrictionServiceStub(grpc.insecure_channel(address))
        try:
            stub.Evaluate(friction_pb2.EvaluateRequest(model="nope"), timeout=10)
            check(False, "unknown model refused")
        except grpc.RpcError as e:
            check(e.code() == grpc.StatusCode.NOT_FOUND and "law" in e.details(), "unknown model: NOT_FOUND listing 'law'")
        try:
            stub.Evaluate(friction_pb2.EvaluateRequest(model="law", contact_pressure=[1e6, 2e6],
                                                       sliding_velocity=[0.1], fibre_angle=[1.0, 1.0]), timeout=10)
            check(False, "unequal arrays refused")
        except grpc.RpcError as e:
            check(e.code() == grpc.StatusCode.INVALID_ARGUMENT and "sliding_velocity" in e.details(),
                  "unequal arrays: INVALID_ARGUMENT naming sliding_velocity")

        # The GP's mu, std and interval from every language.
        answer = stub.Evaluate(friction_pb2.EvaluateRequest(
            model="gp", contact_pressure=queries[:, 0], sliding_velocity=queries[:, 1], temperature=queries[:, 2],
            std=True, ci_level=0.95), timeout=10)
        check_gp_answer("Python over gRPC", np.array(answer.mu), np.array(answer.std), np.array(answer.lo),
                        np.array(answer.hi), ref_mu, ref_std)
        drivers = [("C over gRPC", c_driver, f"grpc://{address}/gp", False),
                   ("C in-process", c_driver, f"file://{tmp}/models/gp.h5", False)]
        if fortran_driver:
            drivers.append(("Fortran module over gRPC", fortran_driver, f"grpc://{address}/gp", True))
        for who, driver, uri, count_first in drivers:
            rows, error = run_driver(driver, uri, queries, count_first)
            check(rows is not None and rows.shape == (len(queries), 5), f"{who}: one answer per point {error}")
            if rows is not None and rows.shape == (len(queries), 5):
                check_gp_answer(who, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], ref_mu, ref_std)
                check(np.all(rows[:, 4] == 0), f"{who}: every point OK (statuses {rows[:, 4].astype(int).tolist()})")
        if args.library:
            check_python_in_process(tmp, queries, ref_mu, ref_std)
        check_example_command_line(address)
        # The meso-trace example of the main job: a trace of Gauss points and the plot of mu over the box.
        trace = subprocess.run([sys.executable, str(Path(args.examples) / "meso_trace.py"), address, "gp", "--points", "300",
                                "--increments", "5", "--plot", str(tmp / "mu.png")],
                               capture_output=True, text=True, timeout=120, env={**os.environ, "PYTHONPATH": args.stubs})
        plotted = (tmp / "mu.png").exists() and (tmp / "mu.png").stat().st_size > 10000
        check(trace.returncode == 0 and "5 increments x 300 Gauss points answered" in trace.stdout and plotted,
              "meso_trace.py: trace answered, table printed, plot written"
              + ("" if trace.returncode == 0 else "\n" + trace.stdout + trace.stderr))
        example = subprocess.run([c_example, f"grpc://{address}/law"], capture_output=True, text=True, timeout=60)
        check(example.returncode == 0, "C example over gRPC: mu of the law and a NaN point refused alone"
              + ("" if example.returncode == 0 else "\n" + example.stdout + example.stderr))
        if args.vfriction:
            example = subprocess.run([args.vfriction, f"grpc://{address}/law"], capture_output=True, text=True,
                                     timeout=60)
            check(example.returncode == 0, "VFRICTION-style Fortran example (F77 entry points) over gRPC"
                  + ("" if example.returncode == 0 else "\n" + example.stdout + example.stderr))
    finally:
        server.send_signal(signal.SIGTERM)
        check(server.wait(timeout=20) == 0, "server drained and exited 0 on SIGTERM")

    # A restarted server is found again within the reconnect schedule of examples/python/mufric_channel.py
    # (regression: gRPC's default backoff, 1 s growing 1.6x, left a call waiting 12 s or more).
    import mufric_channel  # noqa: E402

    def start_server(listen, ready):
        ready.unlink(missing_ok=True)
        process = subprocess.Popen([mufric, "serve", "--models", str(tmp / "models"), "--listen", listen,
                                    "--ready-file", str(ready)], stderr=subprocess.DEVNULL)
        for _ in range(200):
            if ready.exists() and ready.read_text().strip():
                return process, ready.read_text().strip()
            time.sleep(0.05)
        raise SystemExit("serve did not start")

    first, address = start_server("127.0.0.1:0", tmp / "address")
    with mufric_channel.open_channel(address) as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        stub.ListModels(friction_pb2.ListModelsRequest(), timeout=10, wait_for_ready=True)
        first.send_signal(signal.SIGTERM)
        first.wait(timeout=20)
        pending = stub.ListModels.future(friction_pb2.ListModelsRequest(), timeout=60, wait_for_ready=True)
        DOWN_SECONDS, MOST_SECONDS_TO_FIND_IT = 6.0, 2.0  # default backoff would redial at ~5.2 s, then ~9.3 s
        time.sleep(DOWN_SECONDS)
        second, _ = start_server(address, tmp / "address2")
        up = time.monotonic()
        try:
            pending.result()
            waited = time.monotonic() - up
            check(waited < MOST_SECONDS_TO_FIND_IT,
                  f"a server restarted after {DOWN_SECONDS:.0f} s is reached {waited:.2f} s after it is up")
        finally:
            second.send_signal(signal.SIGTERM)
            second.wait(timeout=20)

print(f"{checks - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
