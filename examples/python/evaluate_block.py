#!/usr/bin/python3
"""A Python meso-side client of mufric over gRPC, with stubs generated from proto/mufric/v1.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/evaluate_block.py 127.0.0.1:50051 MODEL

Lists the served models, describes one, and asks for mu with a 95 % interval for a block of three
points spread over the model's box, whatever its inputs (read from DescribeModel: pressure,
velocity, temperature, a composite law's fibre angle); printed in human units, sent in SI (the wire
is SI). A refusal for lack of memory is retried after the server's hint (mufric_channel.call_with_retry).
"""
import sys

from mufric.v1 import friction_pb2, friction_pb2_grpc
from mufric_channel import call_with_retry, open_channel

# SI unit → (factor, offset, human unit) for printing.
HUMAN = {"Pa": (1e-6, 0.0, "MPa"), "m/s": (60.0, 0.0, "m/min"), "K": (1.0, -273.15, "C"), "rad": (57.29577951308232, 0.0, "deg")}
# Where in each input's box the three example points sit.
FRACTIONS = (0.25, 0.5, 0.75)


def human(value, unit):
    factor, offset, shown = HUMAN.get(unit, (1.0, 0.0, unit))
    return f"{value * factor + offset:.4g} {shown}"


def main(address, model, points=None):
    """Evaluates `points` (input name → SI values; default: three points spread over the box)."""
    with open_channel(address) as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        served = stub.ListModels(friction_pb2.ListModelsRequest(), timeout=10, wait_for_ready=True)
        print("serving:", ", ".join(f"{m.name} ({m.kind}, {m.version})" for m in served.models))
        description = stub.DescribeModel(friction_pb2.DescribeModelRequest(model=model), timeout=10, wait_for_ready=True)
        inputs = list(description.inputs)
        print(f"{model}: inputs " + ", ".join(f"{i.name} {human(i.lo, i.unit)} .. {human(i.hi, i.unit)}" for i in inputs))
        if points is None:
            points = {i.name: [i.lo + f * (i.hi - i.lo) for f in FRACTIONS] for i in inputs}
        request = friction_pb2.EvaluateRequest(model=model, ci_level=0.95, **points)
        answer = call_with_retry(stub.Evaluate, request, timeout=10)
        units = {i.name: i.unit for i in inputs}
        for k, (mu, lo, hi, status) in enumerate(zip(answer.mu, answer.lo, answer.hi, answer.status)):
            where = "  ".join(f"{name} {human(values[k], units.get(name, ''))}" for name, values in points.items())
            print(f"{where}  mu {mu:.6f}  95 % [{lo:.6f}, {hi:.6f}]  {friction_pb2.PointStatus.Name(status)}")
        return answer


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051", sys.argv[2] if len(sys.argv) > 2 else "law")
