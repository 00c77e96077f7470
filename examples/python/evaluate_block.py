#!/usr/bin/python3
"""A Python meso-side client of mufric over gRPC, with stubs generated from proto/mufric/v1.

    mufric serve &                 # the shipped models (dry_default, ti6al4v_tin) on 127.0.0.1:50051
    PYTHONPATH=build/python /usr/bin/python3 examples/python/evaluate_block.py [ADDRESS] [MODEL]
        [--p 800MPa 1.2GPa] [--v 100m/min] [--T 500C] [--angle 90deg]

Lists the served models, describes one (default dry_default), and asks for mu with a 95 % interval
at the points given (each input one value or one per point; a single value is used for all), or,
without any, at three points spread over the model's box, whatever its inputs (read from
DescribeModel: pressure, velocity, temperature, a composite law's fibre angle); printed in human
units, sent in SI (the wire is SI). A refusal for lack of memory is retried after the server's hint
(mufric_channel.call_with_retry). A Python code without a server: client/python/mufric_inprocess.py.
"""
import argparse
import re
import sys

import grpc
from mufric.v1 import friction_pb2, friction_pb2_grpc
from mufric_channel import call_with_retry, open_channel

# SI unit → (factor, offset, human unit) for printing.
HUMAN = {"Pa": (1e-6, 0.0, "MPa"), "m/s": (60.0, 0.0, "m/min"), "K": (1.0, -273.15, "C"), "rad": (57.29577951308232, 0.0, "deg")}
# Where in each input's box the three example points sit.
FRACTIONS = (0.25, 0.5, 0.75)


# Units a point may be given in → (kind, factor, offset) to SI.
UNITS = {"Pa": ("p", 1.0, 0.0), "kPa": ("p", 1e3, 0.0), "MPa": ("p", 1e6, 0.0), "GPa": ("p", 1e9, 0.0),
         "m/s": ("v", 1.0, 0.0), "m/min": ("v", 1 / 60, 0.0), "mm/s": ("v", 1e-3, 0.0),
         "K": ("T", 1.0, 0.0), "C": ("T", 1.0, 273.15), "degC": ("T", 1.0, 273.15), "°C": ("T", 1.0, 273.15),
         "deg": ("angle", 0.017453292519943295, 0.0), "rad": ("angle", 1.0, 0.0)}
FLAGS = {"p": "contact_pressure", "v": "sliding_velocity", "T": "temperature", "angle": "fibre_angle"}


def si_value(text, kind, flag):
    """'800MPa' → 8e8, refusing a bare number or a unit of another quantity, naming the flag."""
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(\S+)\s*", text)
    unit = UNITS.get(m.group(2)) if m else None
    if not m or unit is None or unit[0] != kind:
        known = " ".join(u for u, (k, _, _) in UNITS.items() if k == kind)
        raise SystemExit(f"evaluate_block.py: error: --{flag} {text!r}: give a number with a unit ({known}), e.g. "
                         + {"p": "800MPa", "v": "100m/min", "T": "500C", "angle": "90deg"}[kind])
    try:
        return float(m.group(1)) * unit[1] + unit[2]
    except ValueError:
        raise SystemExit(f"evaluate_block.py: error: --{flag} {text!r}: {m.group(1)!r} is not a number")


def points_of(args):
    """{input name: [SI values]} from --p/--v/--T/--angle, one value spread over the others' length."""
    given = {FLAGS[k]: [si_value(t, k, k) for t in getattr(args, k)] for k in FLAGS if getattr(args, k)}
    if not given:
        return None
    lengths = {len(v) for v in given.values()} - {1}
    if len(lengths) > 1:
        raise SystemExit("evaluate_block.py: error: the inputs differ in length: "
                         + ", ".join(f"{name} {len(v)}" for name, v in given.items()))
    n = lengths.pop() if lengths else 1
    return {name: v * n if len(v) == 1 else v for name, v in given.items()}


def human(value, unit):
    factor, offset, shown = HUMAN.get(unit, (1.0, 0.0, unit))
    return f"{value * factor + offset:.4g} {shown}"


def main(address, model, points=None, timeout=10):
    """Evaluates `points` (input name → SI values; default: three points spread over the box)."""
    with open_channel(address) as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        served = stub.ListModels(friction_pb2.ListModelsRequest(), timeout=timeout, wait_for_ready=True)
        print("serving:", ", ".join(f"{m.name} ({m.kind}, {m.version})" for m in served.models))
        description = stub.DescribeModel(friction_pb2.DescribeModelRequest(model=model), timeout=timeout, wait_for_ready=True)
        inputs = list(description.inputs)
        print(f"{model}: inputs " + ", ".join(f"{i.name} {human(i.lo, i.unit)} .. {human(i.hi, i.unit)}" for i in inputs))
        if points is None:
            points = {i.name: [i.lo + f * (i.hi - i.lo) for f in FRACTIONS] for i in inputs}
        request = friction_pb2.EvaluateRequest(model=model, ci_level=0.95, **points)
        answer = call_with_retry(stub.Evaluate, request, timeout=timeout)
        units = {i.name: i.unit for i in inputs}
        for k, (mu, lo, hi, status) in enumerate(zip(answer.mu, answer.lo, answer.hi, answer.status)):
            where = "  ".join(f"{name} {human(values[k], units.get(name, ''))}" for name, values in points.items())
            print(f"{where}  mu {mu:.6f}  95 % [{lo:.6f}, {hi:.6f}]  {friction_pb2.PointStatus.Name(status)}")
        if answer.message:  # which point was outside the box or unanswered, and what was done
            print(" ", answer.message)
        return answer


def command_line():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="e.g. evaluate_block.py 127.0.0.1:50051 ti6al4v_tin --p 900MPa 1.3GPa --v 30m/min --T 800C")
    ap.add_argument("address", nargs="?", default="127.0.0.1:50051", help="host:port of `mufric serve` (default 127.0.0.1:50051)")
    ap.add_argument("model", nargs="?", default="dry_default", help="a served model's name (default dry_default, shipped)")
    for flag, what in (("p", "contact pressure, e.g. 800MPa"), ("v", "sliding velocity, e.g. 100m/min"),
                       ("T", "temperature, e.g. 500C"), ("angle", "fibre angle, e.g. 90deg")):
        ap.add_argument("--" + flag, nargs="+", default=[], metavar="VALUE", help=what + " (one, or one per point)")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for the server per call (default 10)")
    args = ap.parse_args()
    points = points_of(args)
    try:
        main(args.address, args.model, points, args.timeout)
    except grpc.RpcError as e:
        code = e.code()
        if code in (grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.DEADLINE_EXCEEDED):
            why = f"no mufric server answered at {args.address} ({code.name}); start one with `mufric serve`"
        else:
            why = f"{code.name}: {e.details()}"
        print(f"evaluate_block.py: error: {why}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(command_line())
