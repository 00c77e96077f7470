#!/usr/bin/python3
"""The server's memory under the three loads of issue 49 (defect 1), as a user would bring them.

  /usr/bin/python3 bench/benchmarks/server_memory.py --mufric build/app/mufric [--serve-args "--max-memory-mb 512"]

Starts `mufric serve` on the shipped dry_default model and measures its resident memory (VmRSS,
sampled every 10 ms, and the kernel's peak VmHWM, reset before each load through
/proc/PID/clear_refs) through:
  burst    8 concurrent Evaluate calls of 1 M points each with gradient, std and interval, each
           retried after the server's hint when it is refused as busy, as mufric's clients do;
  streams  1000 EvaluateStream calls that each send a 4096-point block (--stream-points) with
           gradient, std and interval, and never read the answer
           (held open 10 s, then dropped);
  oversize 3 concurrent Evaluate calls of 240 MB (7.5 M points x 4 inputs) against the 64 MB limit;
then the idle resident memory 3 s after each. Requests are serialised by hand (packed doubles), so
the client's own cost stays out of the way. Prints one table row per load and the answers' codes.
"""
import argparse
import collections
import os
import random
import shlex
import struct
import subprocess
import sys
import tempfile
import threading
import time

import grpc
import numpy as np


def varint(value):
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def packed_doubles(field, values):
    raw = np.ascontiguousarray(values, dtype="<f8").tobytes()
    return varint(field << 3 | 2) + varint(len(raw)) + raw


def evaluate_request(points, gradient=True, seed=0):
    """EvaluateRequest bytes (proto/mufric/v1/friction.proto): dry_default, points inside its box."""
    rng = np.random.default_rng(seed)
    model = b"dry_default"
    body = varint(1 << 3 | 2) + varint(len(model)) + model
    body += packed_doubles(3, rng.uniform(6e8, 1.2e9, points))   # contact_pressure, Pa
    body += packed_doubles(4, rng.uniform(0.5, 3.0, points))     # sliding_velocity, m/s
    body += packed_doubles(5, rng.uniform(400.0, 800.0, points))  # temperature, K
    if gradient:
        body += varint(7 << 3) + varint(1)                       # std
        body += varint(8 << 3 | 1) + struct.pack("<d", 0.95)     # ci_level
        body += varint(9 << 3) + varint(1)                       # gradient
    return body


def oversized_request(megabytes):
    points = megabytes * 1024 * 1024 // 32
    body = evaluate_request(points, gradient=False)
    return body + packed_doubles(6, np.zeros(points))  # fibre_angle: the fourth input's bytes


def rss_kb(pid, field):
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"no {field} for pid {pid}")


class RssSampler:
    """Largest VmRSS seen while running, and the kernel's VmHWM (reset at start)."""

    def __init__(self, pid):
        self.pid = pid
        self.peak_kb = 0
        self.running = True
        with open(f"/proc/{pid}/clear_refs", "w") as refs:
            refs.write("5")  # resets VmHWM to the current RSS
        self.thread = threading.Thread(target=self.sample, daemon=True)
        self.thread.start()

    def sample(self):
        while self.running:
            self.peak_kb = max(self.peak_kb, rss_kb(self.pid, "VmRSS"))
            time.sleep(0.01)

    def stop(self):
        self.running = False
        self.thread.join()
        return max(self.peak_kb, rss_kb(self.pid, "VmHWM"))


def identity(x):
    return x


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mufric", required=True, help="the mufric executable")
    parser.add_argument("--serve-args", default="", help="extra `mufric serve` options")
    parser.add_argument("--streams", type=int, default=1000)
    parser.add_argument("--hold", type=float, default=10.0, help="seconds the unread streams stay open")
    parser.add_argument("--stream-points", type=int, default=4096, help="points in each stream's block")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="mufric-memory-")
    models = os.path.join(work, "models")
    os.mkdir(models)
    shipped = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(args.mufric))), "share", "mufric", "models",
                           "dry_default.h5")
    os.symlink(shipped, os.path.join(models, "dry_default.h5"))
    ready = os.path.join(work, "address")
    command = [args.mufric, "serve", "--models", models, "--listen", "127.0.0.1:0", "--ready-file", ready]
    command += shlex.split(args.serve_args)
    log = open(os.path.join(work, "server.log"), "w")
    server = subprocess.Popen(command, stderr=log)
    for _ in range(400):
        if os.path.exists(ready) and os.path.getsize(ready) > 0:
            break
        time.sleep(0.05)
    else:
        sys.exit("the server did not start: " + open(os.path.join(work, "server.log")).read())
    address = open(ready).read().strip()
    channel_options = [("grpc.max_send_message_length", -1), ("grpc.max_receive_message_length", -1)]
    start_kb = rss_kb(server.pid, "VmRSS")
    print(f"server {' '.join(command[1:2] + command[7:])}: start RSS {start_kb / 1024:.0f} MB")
    print("| load | peak RSS MB | idle RSS MB after | answers |")
    print("|---|---|---|---|")

    def report(name, sampler, codes):
        peak = sampler.stop()
        time.sleep(3.0)
        idle = rss_kb(server.pid, "VmRSS")
        answers = ", ".join(f"{count} {code}" for code, count in sorted(codes.items()))
        print(f"| {name} | {peak / 1024:.0f} | {idle / 1024:.0f} | {answers} |", flush=True)

    def concurrent_calls(requests, retry=True):
        codes = collections.Counter()
        messages = collections.Counter()
        lock = threading.Lock()

        def call(body):
            channel = grpc.insecure_channel(address, options=channel_options)  # a connection each
            evaluate = channel.unary_unary("/mufric.v1.FrictionService/Evaluate", request_serializer=identity,
                                           response_deserializer=identity)
            details = ""
            pause = 1.0 + random.random()  # mufric's clients: the server's hint, jittered, growing 1.5x
            while True:
                try:
                    evaluate(body, timeout=300)
                    code = "OK"
                except grpc.RpcError as error:
                    code = error.code().name
                    details = error.details()
                    hint = dict(error.trailing_metadata() or ()).get("mufric-retry-after-ms")
                    if "RST_STREAM with error code 11" in details:  # shed by gRPC's transport quota
                        hint = 50
                    if retry and code == "RESOURCE_EXHAUSTED" and hint is not None:
                        with lock:
                            codes["retried"] += 1
                        time.sleep(min(float(hint) * pause, 1000.0) / 1000.0)
                        pause *= 1.5
                        continue
                if code != "OK":
                    with lock:
                        messages[details] += 1
                break
            with lock:
                codes[code] += 1
            channel.close()

        threads = [threading.Thread(target=call, args=(body,)) for body in requests]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for message, count in messages.items():
            print(f"  {count} x {message}", file=sys.stderr)
        return codes

    burst = [evaluate_request(1_000_000, seed=i) for i in range(8)]
    sampler = RssSampler(server.pid)
    report("8 x 1 M points, gradient + std + interval", sampler, concurrent_calls(burst))
    del burst

    # Unread streams: each sends one block and never reads its answer.
    block = evaluate_request(args.stream_points, gradient=True)
    sampler = RssSampler(server.pid)
    channels = [grpc.insecure_channel(address, options=channel_options + [("grpc.use_local_subchannel_pool", 1)])
                for _ in range(max(1, args.streams // 100))]
    calls = []
    release = threading.Event()

    def one_block_then_wait():  # a meso code's stream: one block sent, the stream kept open
        yield block
        release.wait()

    for i in range(args.streams):
        stream = channels[i % len(channels)].stream_stream("/mufric.v1.FrictionService/EvaluateStream",
                                                            request_serializer=identity, response_deserializer=identity)
        calls.append(stream(one_block_then_wait(), timeout=600))
    time.sleep(args.hold)
    codes = collections.Counter()
    for call in calls:
        if call.done():
            codes[call.code().name] += 1
        else:
            codes["open"] += 1
        call.cancel()
    release.set()
    for channel in channels:
        channel.close()
    report(f"{args.streams} streams of {args.stream_points} points never read ({args.hold:.0f} s)", sampler, codes)
    del calls

    oversized = [oversized_request(240) for _ in range(3)]
    sampler = RssSampler(server.pid)
    report("3 x 240 MB requests (limit 64 MB), not retried", sampler, concurrent_calls(oversized, retry=False))
    server.terminate()
    server.wait()


if __name__ == "__main__":
    main()
