#!/usr/bin/python3
"""The Python client end to end: starts `mufric serve` on a free loopback port with a seed-001 law,
runs examples/python/evaluate_block.py against it and checks mu against the closed-form Table 4
law, then checks that an unknown model is NOT_FOUND and unequal arrays are INVALID_ARGUMENT.
Usage: python_client_test.py MUFRIC_EXE PYTHON_STUB_DIR EXAMPLES_DIR"""
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

mufric, stubs, examples = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path[:0] = [stubs, examples]
import grpc  # noqa: E402
from mufric.v1 import friction_pb2, friction_pb2_grpc  # noqa: E402
import evaluate_block  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    (tmp / "models").mkdir()
    subprocess.run([mufric, "law", "seward", "--table", "4", "--out", str(tmp / "models/law.h5")], check=True,
                   capture_output=True)
    server = subprocess.Popen([mufric, "serve", "--models", str(tmp / "models"), "--listen", "127.0.0.1:0",
                               "--ready-file", str(tmp / "address")], stderr=subprocess.DEVNULL)
    try:
        for _ in range(100):
            if (tmp / "address").exists() and (tmp / "address").read_text().strip():
                break
            time.sleep(0.05)
        address = (tmp / "address").read_text().strip()
        answer = evaluate_block.main(address, "law")
        for mu, p, v in zip(answer.mu, [50.0, 120.0, 180.0], [6.0, 10.0, 14.0]):
            expected = min(max(0.149911 + 0.013133 * v - 0.000753 * p, 0.093755565), 0.322395506)
            check(abs(mu - expected) < 1e-12, f"mu at {p} MPa, {v} m/min = {mu:.9f} (closed form {expected:.9f})")
        check(list(answer.ignored_inputs) == ["temperature"], "temperature reported as ignored by the law")
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
    finally:
        server.send_signal(signal.SIGTERM)
        check(server.wait(timeout=20) == 0, "server drained and exited 0 on SIGTERM")

print(f"{6 - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
