#!/usr/bin/env python3
"""Writes the two glTF scenes that measure hierarchy costs: a million triangle instances
(1 000 nodes each drawing a mesh of 1 000 primitives) under a chain of 1 022 nodes and a hub
(`deep.gltf`, the leaves at depth 1 024, `LoadOptions::max_node_depth`), and the same instances
under the hub alone (`flat.gltf`).

    python3 scripts/hierarchy_scenes.py DIR
"""
import base64
import json
import os
import struct
import sys


def scene(chain):
    # Triangles a few thousandths of a unit across, 5 units away: the frame costs the
    # hierarchy and the draws, hardly any shading.
    data = struct.pack("<9f", 0, 0, 0, 0.004, 0, 0, 0, 0.004, 0) + struct.pack("<3H", 0, 1, 2) + b"\0\0"
    nodes = [{"children": [d + 1]} for d in range(chain)]
    hub = len(nodes)
    nodes.append({"children": list(range(hub + 1, hub + 1001))})
    for i in range(1000):
        x, y = (i % 40) * 0.1 - 2.0, (i // 40) * 0.1 - 1.2
        nodes.append({"mesh": 0, "translation": [x, y, -5.0]})
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}] * 1000}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [0.004, 0.004, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
        ],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for name, chain in [("deep.gltf", 1022), ("flat.gltf", 0)]:
        path = os.path.join(out, name)
        with open(path, "w") as f:
            json.dump(scene(chain), f)
        print(path)


if __name__ == "__main__":
    main()
