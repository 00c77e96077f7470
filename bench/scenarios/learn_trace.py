#!/usr/bin/python3
"""A meso code that walks out of its model's box (issue 62's scenario): per pass, Gauss points whose
contact pressure starts low (first contact: REGION_LO to REGION_HI, below a small starting model's box)
and rises along the trace, and others spread over the box, ask the service for mu with a 95 % interval
over gRPC. Prints one CSV line for the pass: in the region, the share of answers that were uncertain
(95 % interval wider than --uncertain-width) or outside the model's box, the median half-width relative
to mu, the version that answered.

    PYTHONPATH=build/python /usr/bin/python3 bench/scenarios/learn_trace.py 127.0.0.1:50051 gp --pass-number 0

Every query reaches the server's --log-uncertain log like a real meso code's, which is what the
learner (mufric learn) reads.
"""
import argparse

import numpy as np
from mufric.v1 import friction_pb2, friction_pb2_grpc
from mufric_channel import call_with_retry, open_channel

EXTRAPOLATED = friction_pb2.PointStatus.Value("POINT_STATUS_EXTRAPOLATED")


def gauss_points(rng, n, region, box):
    """Half the points in the low-pressure region (v, T over the box), half over the box."""
    v_lo, v_hi = box["sliding_velocity"]
    t_lo, t_hi = box["temperature"]
    half = n // 2
    p = np.concatenate([rng.uniform(region[0], region[1], half), rng.uniform(*box["contact_pressure"], n - half)])
    v = rng.uniform(v_lo + 0.1 * (v_hi - v_lo), v_hi - 0.1 * (v_hi - v_lo), n)
    t = rng.uniform(t_lo + 0.1 * (t_hi - t_lo), t_hi - 0.1 * (t_hi - t_lo), n)
    return p, v, t


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("address")
    ap.add_argument("model")
    ap.add_argument("--points", type=int, default=400, help="Gauss points per increment")
    ap.add_argument("--increments", type=int, default=5)
    ap.add_argument("--region", default="150e6:400e6", help="the low-pressure region, Pa lo:hi")
    ap.add_argument("--box", default="400e6:1300e6,0.375:3.3333,298.15:1173.15",
                    help="the meso code's own ranges of p, v, T (Pa, m/s, K), where the other half of its points lie")
    ap.add_argument("--uncertain-width", type=float, default=0.05, help="a 95 %% interval wider than this is uncertain")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--pass-number", type=int, default=0)
    ap.add_argument("--header", action="store_true")
    a = ap.parse_args()
    region = [float(x) for x in a.region.split(":")]
    names = ["contact_pressure", "sliding_velocity", "temperature"]
    box = {n: [float(x) for x in r.split(":")] for n, r in zip(names, a.box.split(","))}
    stub = friction_pb2_grpc.FrictionServiceStub(open_channel(a.address))
    rng = np.random.default_rng(a.seed)
    in_region, uncertain, half_width, versions = 0, 0, [], set()
    for _ in range(a.increments):
        p, v, t = gauss_points(rng, a.points, region, box)
        request = friction_pb2.EvaluateRequest(model=a.model, contact_pressure=p, sliding_velocity=v, temperature=t,
                                               std=True, ci_level=0.95)
        r = call_with_retry(stub.Evaluate, request, timeout=60)
        versions.add(r.version)
        mu, lo, hi = np.array(r.mu), np.array(r.lo), np.array(r.hi)
        status = np.array(r.status)
        region_mask = p < region[1]
        wide = (hi - lo) > a.uncertain_width
        outside = status == EXTRAPOLATED
        in_region += int(region_mask.sum())
        uncertain += int((region_mask & (wide | outside)).sum())
        half_width.extend(((hi - lo) / 2 / mu)[region_mask])
    if a.header:
        print("pass,version,region_points,uncertain_or_outside_share,median_half_width_over_mu")
    print(f"{a.pass_number},{'/'.join(sorted(versions))},{in_region},{uncertain / max(in_region, 1):.4f},"
          f"{float(np.median(half_width)):.4f}")


if __name__ == "__main__":
    main()
