#!/usr/bin/python3
"""A meso-scale chip-formation code's view of mufric: per increment, one block of contact Gauss
points (pressure, sliding velocity, temperature drifting along a trace) asks the service for mu with
a 95 % interval, over gRPC with the stubs generated from proto/mufric/v1.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/meso_trace.py 127.0.0.1:50051 gp \
        --dataset db.h5 --plot mu-over-box.png

Prints a short table (a few Gauss points at the first and last increment) and, with --plot, draws mu
with its 95 % band along each input through the centre of the model's box, with the micro-model
samples of --dataset (if given) near that line.
"""
import argparse
import math

import grpc
import numpy as np
from mufric.v1 import friction_pb2, friction_pb2_grpc
from mufric_channel import call_with_retry, open_channel

HUMAN = {"contact_pressure": (1e-6, "MPa"), "sliding_velocity": (60.0, "m/min"), "temperature": (1.0, "K")}


def human(name, value):
    if name == "temperature":
        return f"{value - 273.15:7.1f} C"
    scale, unit = HUMAN[name]
    return f"{value * scale:7.1f} {unit}"


def evaluate(stub, model, p, v, t):
    request = friction_pb2.EvaluateRequest(model=model, contact_pressure=p, sliding_velocity=v, temperature=t,
                                           std=True, ci_level=0.95)
    return call_with_retry(stub.Evaluate, request, timeout=30)


def trace(stub, model, box, points, increments, seed):
    """Gauss points start spread over the box and drift by a random walk (0.5 % of the box per increment)."""
    rng = np.random.default_rng(seed)
    lo = np.array([box[n][0] for n in HUMAN])
    hi = np.array([box[n][1] for n in HUMAN])
    x = lo + (hi - lo) * (0.15 + 0.7 * rng.random((points, 3)))
    answers = []
    for _ in range(increments):
        answers.append((x.copy(), evaluate(stub, model, x[:, 0], x[:, 1], x[:, 2])))
        x = np.clip(x + 0.005 * (hi - lo) * rng.standard_normal((points, 3)), lo, hi)
    return answers


def print_table(answers, show):
    print(f"{'increment':>9} {'point':>5} {'pressure':>11} {'velocity':>13} {'temperature':>11}   mu      95 % interval")
    for k in (0, len(answers) - 1):
        x, a = answers[k]
        for i in range(show):
            status = friction_pb2.PointStatus.Name(a.status[i]).replace("POINT_STATUS_", "")
            print(f"{k + 1:9d} {i + 1:5d} {human('contact_pressure', x[i, 0]):>11} {human('sliding_velocity', x[i, 1]):>13} "
                  f"{human('temperature', x[i, 2]):>11}   {a.mu[i]:.4f}  [{a.lo[i]:.4f}, {a.hi[i]:.4f}]"
                  f"{'' if status == 'OK' else '  ' + status}")


def plot(stub, model, box, dataset, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(HUMAN)
    centre = np.array([(box[n][0] + box[n][1]) / 2 for n in names])
    samples = None
    if dataset:
        import h5py
        with h5py.File(dataset, "r") as f:
            ok = f["samples/status"][:] == 0
            samples = (f["samples/inputs"][:][ok], f["samples/mu"][:][ok])
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), sharey=True)
    for j, (name, ax) in enumerate(zip(names, axes)):
        line = np.tile(centre, (121, 1))
        line[:, j] = np.linspace(box[name][0], box[name][1], 121)
        a = evaluate(stub, model, line[:, 0], line[:, 1], line[:, 2])
        scale = (lambda s: s - 273.15) if name == "temperature" else (lambda s, c=HUMAN[name][0]: s * c)
        unit = "C" if name == "temperature" else HUMAN[name][1]
        ax.fill_between(scale(line[:, j]), a.lo, a.hi, alpha=0.3, label="95 % interval")
        ax.plot(scale(line[:, j]), a.mu, label="GP mean")
        if samples is not None:
            xs, mus = samples
            others = [k for k in range(3) if k != j]
            width = np.array([box[n][1] - box[n][0] for n in names])
            near = np.all(np.abs(xs[:, others] - centre[others]) <= 0.25 * width[others], axis=1)
            ax.plot(scale(xs[near, j]), mus[near], "k.", label="micro-model runs (other inputs within 25 %)")
        ax.set_xlabel(f"{name} [{unit}]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("friction coefficient mu")
    axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{model}: mu through the centre of the box, with its 95 % interval")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("address", help="host:port of mufric serve")
    parser.add_argument("model", help="model name (file stem in the served directory)")
    parser.add_argument("--points", type=int, default=2000, help="contact Gauss points per increment")
    parser.add_argument("--increments", type=int, default=50)
    parser.add_argument("--show", type=int, default=4, help="Gauss points printed at the first and last increment")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--dataset", help="micro-model dataset (HDF5) to show as points in the plot")
    parser.add_argument("--plot", help="PNG to write: mu with its 95 % band along each input")
    args = parser.parse_args()
    with open_channel(args.address) as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        description = stub.DescribeModel(friction_pb2.DescribeModelRequest(model=args.model), timeout=10, wait_for_ready=True)
        box = {i.name: (i.lo, i.hi) for i in description.inputs}
        missing = [n for n in HUMAN if n not in box]
        if missing:
            raise SystemExit(f"model {args.model} lacks the inputs {missing}")
        answers = trace(stub, args.model, box, args.points, args.increments, args.seed)
        widths = np.concatenate([np.array(a.hi) - np.array(a.lo) for _, a in answers])
        print(f"{args.increments} increments x {args.points} Gauss points answered; 95 % interval width "
              f"median {np.median(widths):.4f}, max {widths.max():.4f}")
        print_table(answers, args.show)
        if args.plot:
            plot(stub, args.model, box, args.dataset, args.plot)


if __name__ == "__main__":
    main()
