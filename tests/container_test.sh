#!/usr/bin/env bash
# The container is real: builds deploy/Dockerfile with podman from a Debian 12 base image made
# offline with mmdebstrap (no registry is reachable here; Debian's archive is), runs `mufric serve`
# in it with a model directory mounted read-only, and from the host asks grpc.health.v1 and an
# Evaluate (mufric predict) over loopback. Exit 77 (skipped) with the reason where podman cannot run.
# Usage: tests/container_test.sh SOURCE_DIR MUFRIC [prebuilt|source]
#   prebuilt (default): the image takes MUFRIC, this build's portable executable (the test command);
#   source: the Dockerfile compiles mufric from SOURCE_DIR inside the image (~8 min; the long tests).
set -uo pipefail
source_dir=$(realpath "$1") mufric=$(realpath "$2") binary=${3:-prebuilt}
[[ $binary == prebuilt || $binary == source ]] || { echo "container_test: third argument '$binary' is neither prebuilt nor source" >&2; exit 2; }
skip() { echo "SKIPPED: $*"; exit 77; }
command -v podman >/dev/null || skip "podman is not installed (deploy/install-deps.sh installs it)"
command -v mmdebstrap >/dev/null || skip "mmdebstrap is not installed"
[[ $(id -u) == 0 ]] || skip "needs root (rootful podman with runc and the offline Debian base image mmdebstrap builds)"
export CONTAINERS_CONF=$source_dir/deploy/podman/containers.conf
podman info >/dev/null 2>&1 || skip "podman cannot run here: $(podman info 2>&1 | tail -1)"
set -e
work=$(mktemp -d)
container=""
trap '[[ -n $container ]] && podman rm -f "$container" >/dev/null 2>&1; rm -rf "$work"' EXIT
base=localhost/debian:12
if ! podman image exists "$base"; then
  echo "building the base image $base with mmdebstrap (Debian 12 minbase, ~35 s)"
  mmdebstrap --quiet --variant=minbase bookworm "$work/bookworm.tar"
  podman import --quiet "$work/bookworm.tar" "$base" >/dev/null
  rm -f "$work/bookworm.tar"
fi
start=$(date +%s)
mkdir -p "$work/context"
if [[ $binary == source ]]; then
  echo "building deploy/Dockerfile (a portable release build of mufric, then its runtime image)"
  # Only what the image build reads: no build directories, no git history.
  tar -C "$source_dir" --exclude='./build*' --exclude=./.git --exclude='./mufric-out' -cf - . | tar -C "$work/context" -xf -
else
  echo "building deploy/Dockerfile's runtime image around $mufric (BINARY=prebuilt)"
  if ldd "$mufric" | grep -q 'libasan\|libtsan\|libubsan'; then echo "$mufric is a sanitizer build, not a release one"; exit 1; fi
  cp "$mufric" "$work/context/mufric"
fi
podman build --quiet --network host --build-arg BASE=$base --build-arg BINARY=$([[ $binary == source ]] && echo build || echo prebuilt) \
  -t localhost/mufric:test -f "$source_dir/deploy/Dockerfile" "$work/context" > "$work/build.log" 2>&1 ||
  { tail -30 "$work/build.log"; exit 1; }
echo "image built in $(( $(date +%s) - start )) s: $(podman image inspect localhost/mufric:test --format '{{.Size}}' | awk '{ printf "%.0f MB", $1 / 1e6 }')"
mkdir -p "$work/models"
"$mufric" law seward --table 4 --out "$work/models/law.h5" >/dev/null
chmod -R a+rX "$work/models"
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
container=$(podman run -d --network host -v "$work/models:/models:ro" localhost/mufric:test \
  mufric serve --models /models --listen "127.0.0.1:$port")
for _ in $(seq 100); do
  "$mufric" status "grpc://127.0.0.1:$port" >/dev/null 2>&1 && break
  sleep 0.1
done
/usr/bin/python3 - "$port" <<'PY'
import sys, grpc
# grpc.health.v1.Health/Check with an empty HealthCheckRequest; the answer's field 1 is the status.
channel = grpc.insecure_channel(f"127.0.0.1:{sys.argv[1]}")
check = channel.unary_unary("/grpc.health.v1.Health/Check", request_serializer=lambda b: b, response_deserializer=lambda b: b)
answer = check(b"", timeout=10)
assert answer == b"\x08\x01", f"health: {answer!r} is not SERVING"
print("health: SERVING")
PY
answer=$("$mufric" predict --model "grpc://127.0.0.1:$port/law" --p 80MPa --v 10m/min --angle 90deg)
echo "$answer"
# Seed 001 Table 4, 90°: 0.149911 + 0.013133·10 − 0.000753·80 = 0.221001
grep -q "mu = 0.221001" <<< "$answer" || { echo "wrong answer from the container"; podman logs "$container"; exit 1; }
echo "container test passed"
