"""The faulty site's scene swap (bench/scenarios/faulty_site): rewrites a database's scene attributes in place.
  swap_scene.py DB --set "a.b=V c.d=W"       the scene with these values set (added where absent; its SHA-256 to match)
  swap_scene.py DB --from OTHER.h5          OTHER's scene, byte for byte
"""
import argparse
import hashlib
import json

import h5py

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("db")
group = parser.add_mutually_exclusive_group(required=True)
group.add_argument("--set", help="dotted.key=VALUE assignments separated by spaces (numbers as numbers, anything else as a string)")
group.add_argument("--from", dest="source", help="a database whose scene to copy")
args = parser.parse_args()


def text_of(value):
    return value.decode() if isinstance(value, bytes) else str(value)


if args.source:
    with h5py.File(args.source, "r") as f:
        scene = text_of(f.attrs["scene_json"])
else:
    with h5py.File(args.db, "r") as f:
        tree = json.loads(text_of(f.attrs["scene_json"]))
    for assignment in args.set.split():
        key, value = assignment.split("=", 1)
        *path, leaf = key.split(".")
        node = tree
        for part in path:
            node = node.setdefault(part, {})
        try:
            node[leaf] = json.loads(value)
        except json.JSONDecodeError:
            node[leaf] = value
    scene = json.dumps(tree, indent=2, sort_keys=True)
with h5py.File(args.db, "r+") as f:
    f.attrs.modify("scene_json", scene)
    f.attrs.modify("scene_sha256", hashlib.sha256(scene.encode()).hexdigest())
