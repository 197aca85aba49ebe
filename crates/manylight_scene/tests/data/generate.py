#!/usr/bin/env python3
"""Writes the small valid glTF fixtures of the manylight_scene tests (standard library only).

- bom_ok.gltf: a triangle whose JSON starts with a UTF-8 byte-order mark (accepted).
- png16.gltf + png16.png: a textured triangle whose base-colour texture is a 16-bit RGBA PNG.
- features.gltf: no `scenes` (root nodes are used), a TRS hierarchy, a non-indexed primitive,
  a POINTS primitive (skipped), a point light without range, a spot light (skipped), a camera
  without zfar (infinite) and a primitive without material.
- triangle.glb: a textured triangle in a GLB whose 8-bit PNG texture lives in a buffer view.
- extras_any_type.gltf: a triangle whose `extras` are a string, an array, a number, `null`,
  `true` and a nested object (the spec allows any JSON value there).
- huge_znear.gltf: a triangle and an infinite camera (no zfar) whose znear is 3.4e38.
"""
import base64, json, struct, zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
POSITIONS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
UVS = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
INDICES = struct.pack("<3H", 0, 1, 2) + b"\0\0"


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def png16(width, height, rgba16):
    def chunk(kind, payload):
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))
    row = b"\0" + struct.pack(">4H", *rgba16) * width
    ihdr = struct.pack(">IIBBBBB", width, height, 16, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(row * height))
            + chunk(b"IEND", b""))


def png8(width, height, rgba):
    def chunk(kind, payload):
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))
    row = b"\0" + bytes(rgba) * width
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(row * height))
            + chunk(b"IEND", b""))


def triangle(buffer, accessors, views, attributes):
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 1}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(buffer), "uri": data_uri(buffer)}],
    }


POS_ACC = {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}
IDX_ACC = {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}


def main():
    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
                   {"POSITION": 0})
    (HERE / "bom_ok.gltf").write_bytes(b"\xef\xbb\xbf" + json.dumps(doc, indent=1).encode())

    buf = POSITIONS + INDICES + UVS
    doc = triangle(buf, [POS_ACC, IDX_ACC,
                         {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
                   {"POSITION": 0, "TEXCOORD_0": 2})
    doc["materials"] = [{"name": "png16", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "baseColorFactor": [1, 0.5, 1, 1],
        "metallicFactor": 0, "roughnessFactor": 0.5}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    doc["textures"] = [{"source": 0}]
    doc["images"] = [{"uri": "png16.png"}]
    (HERE / "png16.gltf").write_text(json.dumps(doc, indent=1))
    (HERE / "png16.png").write_bytes(png16(4, 4, (0xFFFF, 0x8000, 0x0000, 0xFFFF)))

    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.25], "intensity": 4.0},
            {"type": "spot", "intensity": 10.0, "spot": {}},
        ]}},
        "nodes": [
            {"translation": [10, 0, 0], "scale": [2, 2, 2], "children": [1, 2]},
            {"translation": [0, 1, 0], "mesh": 0},
            {"translation": [0, 0, 5], "rotation": [0, 0.7071068, 0, 0.7071068], "camera": 0,
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}, "mesh": 1},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05}}],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}}]},
            {"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]},
        ],
        "accessors": [POS_ACC],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": data_uri(POSITIONS)}],
    }
    (HERE / "features.gltf").write_text(json.dumps(doc, indent=1))

    doc = triangle(POSITIONS + INDICES, [dict(POS_ACC, extras=None), dict(IDX_ACC, extras=[1, 2])],
                   [{"buffer": 0, "byteLength": 36, "extras": 5},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
                   {"POSITION": 0})
    doc["extras"] = "a string"
    doc["asset"]["extras"] = {"nested": {"deeper": [1, {"x": True}]}}
    doc["nodes"][0]["extras"] = True
    doc["meshes"][0]["extras"] = [[], {}]
    doc["meshes"][0]["primitives"][0]["extras"] = 0.5
    doc["scenes"][0]["extras"] = None
    (HERE / "extras_any_type.gltf").write_text(json.dumps(doc, indent=1))

    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
                   {"POSITION": 0})
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 3.4e38}}]
    doc["nodes"][0]["camera"] = 0
    (HERE / "huge_znear.gltf").write_text(json.dumps(doc, indent=1))

    image = png8(2, 2, (0, 255, 0, 255))
    image += b"\0" * (-len(image) % 4)
    bin_chunk = POSITIONS + INDICES + UVS + image
    doc = triangle(b"", [POS_ACC, IDX_ACC,
                         {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 68, "byteLength": len(image)}],
                   {"POSITION": 0, "TEXCOORD_0": 2})
    doc["buffers"] = [{"byteLength": len(bin_chunk)}]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    doc["textures"] = [{"source": 0}]
    doc["images"] = [{"bufferView": 3, "mimeType": "image/png"}]
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    body = struct.pack("<I4s", len(j), b"JSON") + j + struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    (HERE / "triangle.glb").write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


if __name__ == "__main__":
    main()
