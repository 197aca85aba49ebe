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
- orthographic_camera.gltf: a triangle and an orthographic camera (xmag 3, ymag 2, znear 0,
  zfar 50) on a node moved to (0, 0, 5).

Files the specification allows that strict parsers refuse (one per family):
- integers_as_floats.gltf: every integer (indices, counts, lengths, offsets, component types,
  index arrays) written with a zero fraction (`3.0`).
- extras_everywhere.gltf: non-object `extras` on every kind of object that may carry them
  (cameras, materials, texture infos, samplers, images, skins, animations, sparse accessors,
  KHR_lights_punctual, ...), with a light, a camera and a texture that must still load.
- scene_without_nodes.gltf: `"scenes": [{}]` (an empty scene) next to nodes no scene uses.
- animation_channel_without_node.gltf: an animation with one channel targeting node 0 and one
  whose target has no `node` (ignored, as the specification says).
- data_uri_percent.gltf: the buffer is a `data:application/octet-stream,...` URI without
  `;base64` (RFC 2397: percent-encoded bytes), the image a `data:image/png,...` one.
- unused_buffer_without_uri.gltf / .glb: a second buffer without `uri` that nothing reads (in
  the GLB, besides buffer 0, the binary chunk).
- several_buffers.glb + several_buffers.bin: a GLB whose buffer 0 is the binary chunk, buffer 1
  an external file (the indices) and buffer 2 a `data:` URI (TEXCOORD_0).
- quantized.gltf: KHR_mesh_quantization: four triangles whose positions, normals and texture
  coordinates are (normalized or not) BYTE, UNSIGNED_BYTE, SHORT and UNSIGNED_SHORT, each on a
  node whose transform carries the dequantisation scale and offset.
"""
import base64, json, struct, urllib.parse, zlib
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

    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
                   {"POSITION": 0})
    doc["cameras"] = [{"type": "orthographic",
                       "orthographic": {"xmag": 3.0, "ymag": 2.0, "znear": 0.0, "zfar": 50.0}}]
    doc["nodes"].append({"camera": 0, "translation": [0.0, 0.0, 5.0]})
    doc["scenes"][0]["nodes"].append(1)
    (HERE / "orthographic_camera.gltf").write_text(json.dumps(doc, indent=1))

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

    spec_allowed()


def pad4(b):
    return b + b"\0" * (-len(b) % 4)


def percent_data_uri(data, mime="application/octet-stream"):
    return f"data:{mime}," + urllib.parse.quote_from_bytes(data, safe="")


def glb(doc, bin_chunk):
    j = pad4(json.dumps(doc).encode()).replace(b"\0", b" ")
    body = (struct.pack("<I4s", len(j), b"JSON") + j
            + struct.pack("<I4s", len(pad4(bin_chunk)), b"BIN\0") + pad4(bin_chunk))
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def floats_for_integers(value):
    """The same document with every int written as a float (`3` becomes `3.0`)."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return float(value)
    if isinstance(value, list):
        return [floats_for_integers(v) for v in value]
    if isinstance(value, dict):
        return {k: floats_for_integers(v) for k, v in value.items()}
    return value


def spec_allowed():
    views = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}]

    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC], views, {"POSITION": 0})
    doc["nodes"] = [{"children": [1]}, {"mesh": 0, "translation": [0, 0, 2]}]
    doc = floats_for_integers(doc)
    text = json.dumps(doc, indent=1)
    assert '"count": 3.0' in text and '"componentType": 5126.0' in text and '"indices": 1.0' in text
    (HERE / "integers_as_floats.gltf").write_text(text)

    buf = POSITIONS + INDICES + UVS
    png = pad4(png8(2, 2, (0, 0, 255, 255)))
    buf += png
    doc = triangle(buf, [dict(POS_ACC, sparse={
        "count": 1, "extras": "sparse",
        "indices": {"bufferView": 1, "componentType": 5123, "extras": 1},
        "values": {"bufferView": 0, "extras": [2]}}),
        IDX_ACC, {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2", "extras": 3.5}],
        views + [{"buffer": 0, "byteOffset": 44, "byteLength": 24, "extras": "view"},
                 {"buffer": 0, "byteOffset": 68, "byteLength": len(png), "extras": False}],
        {"POSITION": 0, "TEXCOORD_0": 2})
    doc["buffers"][0]["extras"] = 42
    doc["extras"] = [1, "root"]
    doc["asset"]["extras"] = "asset"
    doc["scenes"][0]["extras"] = 7
    doc["nodes"] = [{"mesh": 0, "extras": "node", "children": [1]},
                    {"camera": 0, "translation": [0, 0, 3], "extras": None,
                     "extensions": {"KHR_lights_punctual": {"light": 0, "extras": "light ref"}}}]
    doc["meshes"][0]["extras"] = False
    doc["meshes"][0]["primitives"][0].update(material=0, extras="primitive")
    doc["extensionsUsed"] = ["KHR_lights_punctual"]
    doc["extensions"] = {"KHR_lights_punctual": {"extras": "lights", "lights": [
        {"type": "point", "intensity": 2.0, "extras": ["light"]}]}}
    doc["cameras"] = [{"type": "perspective", "extras": "camera",
                       "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 50, "extras": 0}}]
    info = {"index": 0, "extras": "texture info"}
    doc["materials"] = [{"extras": "material",
                         "pbrMetallicRoughness": {"baseColorTexture": info, "extras": 1.25,
                                                  "metallicRoughnessTexture": info},
                         "normalTexture": dict(info, scale=1, extras=["normal"]),
                         "occlusionTexture": dict(info, strength=1, extras=None),
                         "emissiveTexture": dict(info, extras=True)}]
    doc["textures"] = [{"source": 0, "sampler": 0, "extras": "texture"}]
    doc["samplers"] = [{"magFilter": 9729, "extras": "sampler"}]
    doc["images"] = [{"bufferView": 3, "mimeType": "image/png", "extras": ["image"]}]
    doc["skins"] = [{"joints": [0], "extras": "skin"}]
    doc["animations"] = [{"extras": "animation",
                          "samplers": [{"input": 2, "output": 2, "extras": "sampler"}],
                          "channels": [{"sampler": 0, "extras": 9,
                                        "target": {"node": 0, "path": "scale", "extras": "target"}}]}]
    (HERE / "extras_everywhere.gltf").write_text(json.dumps(doc, indent=1))

    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC], views, {"POSITION": 0})
    doc["scenes"] = [{}]
    (HERE / "scene_without_nodes.gltf").write_text(json.dumps(doc, indent=1))

    times = struct.pack("<2f", 0, 1)
    moves = struct.pack("<6f", 0, 0, 0, 0, 1, 0)
    buf = POSITIONS + INDICES + times + moves
    doc = triangle(buf, [POS_ACC, IDX_ACC,
                         {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR",
                          "min": [0], "max": [1]},
                         {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
                   views + [{"buffer": 0, "byteOffset": 44, "byteLength": 8},
                            {"buffer": 0, "byteOffset": 52, "byteLength": 24}],
                   {"POSITION": 0})
    doc["animations"] = [{"samplers": [{"input": 2, "output": 3}], "channels": [
        {"sampler": 0, "target": {"node": 0, "path": "translation"}},
        {"sampler": 0, "target": {"path": "translation", "extensions": {"EXT_example": {}}}}]}]
    (HERE / "animation_channel_without_node.gltf").write_text(json.dumps(doc, indent=1))

    buf = POSITIONS + INDICES
    doc = triangle(buf, [POS_ACC, IDX_ACC], views, {"POSITION": 0})
    doc["buffers"][0]["uri"] = percent_data_uri(buf)
    doc["meshes"][0]["primitives"][0]["material"] = 0
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["textures"] = [{"source": 0}]
    doc["images"] = [{"uri": percent_data_uri(png8(1, 1, (255, 0, 0, 255)), "image/png")}]
    (HERE / "data_uri_percent.gltf").write_text(json.dumps(doc, indent=1))

    doc = triangle(POSITIONS + INDICES, [POS_ACC, IDX_ACC], views, {"POSITION": 0})
    doc["buffers"].append({"byteLength": 1024})
    (HERE / "unused_buffer_without_uri.gltf").write_text(json.dumps(doc, indent=1))

    (HERE / "several_buffers.bin").write_bytes(INDICES)
    doc = triangle(b"", [POS_ACC, IDX_ACC,
                         {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}],
                   [{"buffer": 0, "byteLength": 36}, {"buffer": 1, "byteLength": 6},
                    {"buffer": 2, "byteLength": 24}],
                   {"POSITION": 0, "TEXCOORD_0": 2})
    doc["buffers"] = [{"byteLength": 36}, {"byteLength": 6, "uri": "several_buffers.bin"},
                      {"byteLength": 24, "uri": data_uri(UVS)}]
    (HERE / "several_buffers.glb").write_bytes(glb(doc, POSITIONS))

    doc = triangle(b"", [POS_ACC, IDX_ACC], views, {"POSITION": 0})
    doc["buffers"] = [{"byteLength": 44}, {"byteLength": 4096}]
    (HERE / "unused_buffer_without_uri.glb").write_bytes(glb(doc, POSITIONS + INDICES))

    # KHR_mesh_quantization: (positions, normals, texcoords, node transform) per triangle, each
    # attribute as (accessor fields, struct format, values); byteStride keeps elements 4-aligned.
    BYTE, UBYTE, SHORT, USHORT = 5120, 5121, 5122, 5123
    fmt = {BYTE: "b", UBYTE: "B", SHORT: "h", USHORT: "H"}
    triangles = [
        (({"componentType": SHORT}, [(-1000, 0, 0), (1000, 0, 0), (0, 1000, 0)]),
         ({"componentType": BYTE, "normalized": True}, [(0, 0, 127)] * 3),
         ({"componentType": USHORT, "normalized": True}, [(0, 0), (65535, 0), (0, 32768)]),
         {"scale": [0.001, 0.001, 0.001]}),
        (({"componentType": UBYTE, "normalized": True}, [(0, 0, 0), (255, 0, 0), (0, 255, 0)]),
         ({"componentType": SHORT, "normalized": True}, [(0, 0, 32767), (0, 0, 32767), (0, -32768, 0)]),
         ({"componentType": BYTE, "normalized": True}, [(0, 0), (127, 0), (0, -128)]),
         {"translation": [5, 0, 0], "scale": [2, 2, 2]}),
        (({"componentType": BYTE}, [(-2, 0, 0), (2, 0, 0), (0, 3, 0)]),
         None,
         ({"componentType": UBYTE}, [(0, 0), (1, 0), (0, 2)]),
         {"translation": [0, 5, 0]}),
        (({"componentType": SHORT, "normalized": True}, [(-32768, 0, 0), (32767, 0, 0), (0, 32767, 0)]),
         None,
         ({"componentType": SHORT}, [(0, 0), (1, 0), (-1, 1)]),
         {"translation": [0, 0, 5]}),
    ]
    buf, views, accessors, meshes, nodes = b"", [], [], [], []
    for pos, nor, uv, transform in triangles:
        attributes = {}
        for name, attr, ty in (("POSITION", pos, "VEC3"), ("NORMAL", nor, "VEC3"), ("TEXCOORD_0", uv, "VEC2")):
            if attr is None:
                continue
            fields, values = attr
            f = "<" + fmt[fields["componentType"]] * len(values[0])
            stride = (struct.calcsize(f) + 3) // 4 * 4
            data = b"".join(pad4(struct.pack(f, *v)) if stride > struct.calcsize(f) else struct.pack(f, *v)
                            for v in values)
            views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "byteStride": stride})
            accessors.append(dict(fields, bufferView=len(views) - 1, count=3, type=ty))
            if name == "POSITION":
                accessors[-1]["min"] = [min(v[i] for v in values) for i in range(3)]
                accessors[-1]["max"] = [max(v[i] for v in values) for i in range(3)]
            attributes[name] = len(accessors) - 1
            buf += data
        meshes.append({"primitives": [{"attributes": attributes, "indices": 0}]})
        nodes.append(dict(transform, mesh=len(meshes) - 1))
    views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": 6})
    accessors.insert(0, {"bufferView": len(views) - 1, "componentType": USHORT, "count": 3, "type": "SCALAR"})
    for m in meshes:
        m["primitives"][0]["attributes"] = {k: v + 1 for k, v in m["primitives"][0]["attributes"].items()}
    buf += INDICES
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(buf), "uri": data_uri(buf)}],
    }
    (HERE / "quantized.gltf").write_text(json.dumps(doc, indent=1))


if __name__ == "__main__":
    main()
