"""A gRPC channel to `mufric serve` that finds a restarted server quickly.

gRPC's own reconnect backoff starts at 1 s and grows to 120 s, so a meso code whose server restarted
(a new model deployed, a node rebooted) waited 12 s or more before its next call got through. The
C++ client redials on its retry schedule (50 ms, doubling, four times); this is the same for Python.
Calls should also pass wait_for_ready=True, so that a call made while the channel reconnects waits
for it (up to its timeout) instead of failing at once with UNAVAILABLE.

    from mufric_channel import open_channel, call_with_retry
    with open_channel("127.0.0.1:50051") as channel:
        stub = friction_pb2_grpc.FrictionServiceStub(channel)
        call_with_retry(stub.Evaluate, request, timeout=30)

A server that is out of memory for calls in flight refuses a call with RESOURCE_EXHAUSTED and the
trailing metadata `mufric-retry-after-ms`: call_with_retry waits that long and tries again, as the C++
client does.
"""
import time

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


# The server's retry hint on a RESOURCE_EXHAUSTED refusal (server/friction_service.cpp).
RETRY_AFTER_KEY = "mufric-retry-after-ms"


def call_with_retry(method, request, timeout, attempts=8, sleep=time.sleep):
    """Calls a unary stub method (wait_for_ready=True); a refusal that carries the server's retry hint
    is retried after the pause it asks for, at most `attempts` calls in all; anything else is raised."""
    for attempt in range(attempts):
        try:
            return method(request, timeout=timeout, wait_for_ready=True)
        except grpc.RpcError as error:
            hint = dict(error.trailing_metadata() or ()).get(RETRY_AFTER_KEY)
            if error.code() != grpc.StatusCode.RESOURCE_EXHAUSTED or hint is None or attempt == attempts - 1:
                raise
            sleep(int(hint) / 1000.0)
    raise RuntimeError("unreachable")
