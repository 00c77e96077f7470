"""A gRPC channel to `mufric serve` that finds a restarted server quickly.

gRPC's own reconnect backoff starts at 1 s and grows to 120 s, so a meso code whose server restarted
(a new model deployed, a node rebooted) waited 12 s or more before its next call got through. The
C++ client redials on its retry schedule (50 ms, doubling, four times); this is the same for Python.
Calls should also pass wait_for_ready=True, so that a call made while the channel reconnects waits
for it (up to its timeout) instead of failing at once with UNAVAILABLE.

    from mufric_channel import open_channel
    with open_channel("127.0.0.1:50051") as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        stub.Evaluate(request, timeout=30, wait_for_ready=True)
"""
import grpc

# Milliseconds: the first redial after a lost connection, and the longest pause between redials.
FIRST_RECONNECT_MS = 50
LONGEST_RECONNECT_MS = 800

RECONNECT_OPTIONS = [
    ("grpc.initial_reconnect_backoff_ms", FIRST_RECONNECT_MS),
    ("grpc.min_reconnect_backoff_ms", FIRST_RECONNECT_MS),
    ("grpc.max_reconnect_backoff_ms", LONGEST_RECONNECT_MS),
]


def open_channel(address, max_message_mb=64):
    """An insecure channel to host:port with mufric's reconnect schedule and message size limit."""
    size = max_message_mb * 1024 * 1024
    return grpc.insecure_channel(address, options=RECONNECT_OPTIONS + [
        ("grpc.max_receive_message_length", size), ("grpc.max_send_message_length", size)])
