#!/usr/bin/python3
"""A Python meso-side client of mufric over gRPC, with stubs generated from proto/mufric/v1.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/evaluate_block.py 127.0.0.1:50051 law

Lists the served models, describes one, and asks for mu with a 95 % interval for a block of points
given in human units (converted to SI here: the wire is SI).
"""
import math
import sys

import grpc
from mufric.v1 import friction_pb2, friction_pb2_grpc
from mufric_channel import open_channel


def main(address, model):
    with open_channel(address) as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        served = stub.ListModels(friction_pb2.ListModelsRequest(), timeout=10, wait_for_ready=True)
        print("serving:", ", ".join(f"{m.name} ({m.kind}, {m.version})" for m in served.models))
        description = stub.DescribeModel(friction_pb2.DescribeModelRequest(model=model), timeout=10, wait_for_ready=True)
        print(f"{model}: inputs", [(i.name, i.unit) for i in description.inputs])
        pressure_mpa = [50.0, 120.0, 180.0]
        velocity_m_min = [6.0, 10.0, 14.0]
        request = friction_pb2.EvaluateRequest(
            model=model,
            contact_pressure=[p * 1e6 for p in pressure_mpa],
            sliding_velocity=[v / 60.0 for v in velocity_m_min],
            temperature=[293.15] * 3,
            fibre_angle=[math.pi / 2] * 3,
            ci_level=0.95,
        )
        answer = stub.Evaluate(request, timeout=10, wait_for_ready=True)
        for p, v, mu, lo, hi, status in zip(pressure_mpa, velocity_m_min, answer.mu, answer.lo, answer.hi,
                                            answer.status):
            print(f"p {p:6.1f} MPa  v {v:5.1f} m/min  mu {mu:.6f}  95 % [{lo:.6f}, {hi:.6f}]  "
                  f"{friction_pb2.PointStatus.Name(status)}")
        return answer


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051", sys.argv[2] if len(sys.argv) > 2 else "law")
