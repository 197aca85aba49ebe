#!/usr/bin/env python3
"""Writes the malformed glTF fixtures in this folder (standard library only).

Run `python3 generate.py` here; README.md lists each file and the error it must produce.
Each file is a small variation of one valid triangle so that exactly one thing is wrong.
"""
import base64, copy, json, struct, zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent

POSITIONS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)  # 36 bytes
INDICES = struct.pack("<3H", 0, 1, 2) + b"\0\0"             # 6 bytes + 2 padding
BUFFER = POSITIONS + INDICES                                  # 44 bytes


def data_uri(data, mime="application/octet-stream"):
    return f"data:{mime};base64," + base64.b64encode(data).decode()


def png(width, height, bit_depth=8, color_type=6, idat=None):
    def chunk(kind, payload):
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    if idat is None:
        channels = {0: 1, 2: 3, 4: 2, 6: 4}[color_type]
        row = b"\0" + b"\x7f" * (width * channels * bit_depth // 8)
        idat = zlib.compress(row * height)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def base_doc(buffer=BUFFER):
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
        ],
        "buffers": [{"byteLength": len(buffer), "uri": data_uri(buffer)}],
    }


def with_texture(doc, image):
    doc = copy.deepcopy(doc)
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    doc["textures"] = [{"source": 0}]
    doc["images"] = [image]
    return doc


def write_json(name, doc):
    (HERE / name).write_text(json.dumps(doc, separators=(",", ":")))


def glb(doc, bin_chunk=None):
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    out = struct.pack("<I4s", len(j), b"JSON") + j
    if bin_chunk is not None:
        bin_chunk += b"\0" * (-len(bin_chunk) % 4)
        out += struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    return struct.pack("<4sII", b"glTF", 2, 12 + len(out)) + out


def main():
    (HERE / "empty.gltf").write_bytes(b"")
    (HERE / "invalid_json.gltf").write_text('{"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}')
    write_json("not_gltf.gltf", {"hello": "world"})

    # GLB: header claims 1000 bytes; file is shorter.
    d = base_doc()
    del d["buffers"][0]["uri"]
    good = glb(d, BUFFER)
    (HERE / "truncated.glb").write_bytes(good[:8] + struct.pack("<I", 1000) + good[12:])
    # GLB: total length right, JSON chunk length larger than what follows.
    bad = bytearray(good)
    bad[12:16] = struct.pack("<I", len(good))
    (HERE / "bad_chunk_length.glb").write_bytes(bytes(bad))
    # GLB whose buffer 0 has no uri but which has no BIN chunk.
    (HERE / "glb_without_bin.glb").write_bytes(glb(d))

    d = base_doc(); d["buffers"][0]["uri"] = "does_not_exist.bin"
    write_json("missing_buffer.gltf", d)
    d = base_doc(BUFFER[:20]); d["buffers"][0]["byteLength"] = 44
    write_json("short_buffer.gltf", d)
    d = base_doc(); d["buffers"][0]["uri"] = "data:application/octet-stream;base64,!!not base64!!"
    write_json("bad_base64.gltf", d)
    d = base_doc(); d["buffers"][0]["uri"] = "http://example.com/triangle.bin"
    write_json("http_uri.gltf", d)
    d = base_doc(); d["bufferViews"][0]["byteOffset"] = 40
    write_json("view_out_of_range.gltf", d)
    d = base_doc(); d["accessors"][0]["count"] = 30
    write_json("accessor_out_of_range.gltf", d)
    d = base_doc(); d["bufferViews"][0]["byteStride"] = 4
    write_json("stride_too_small.gltf", d)
    d = base_doc(); d["accessors"][0]["componentType"] = 5121
    write_json("wrong_component_type.gltf", d)
    d = base_doc(); d["accessors"][0]["type"] = "VEC2"
    write_json("position_vec2.gltf", d)
    d = base_doc(POSITIONS + struct.pack("<3H", 0, 1, 7) + b"\0\0")
    write_json("index_out_of_range.gltf", d)
    nan = struct.pack("<9f", 0, 0, 0, float("nan"), 0, 0, 0, 1, 0)
    write_json("nan_position.gltf", base_doc(nan + INDICES))
    d = base_doc(); d["nodes"][0]["mesh"] = 5
    write_json("missing_reference.gltf", d)
    d = base_doc(); d["scenes"][0]["nodes"] = [1]; d["nodes"] = [{"mesh": 0}, {"children": [2]}, {"children": [1]}]
    write_json("node_cycle.gltf", d)
    d = base_doc(); d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write_json("draco_required.gltf", d)

    # Transforms: 1e39 overflows f32 to infinity; JSON has no NaN literal.
    d = base_doc(); d["nodes"][0]["translation"] = [1e39, 0, 0]
    write_json("nan_transform.gltf", d)
    d = base_doc(); d["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1e39, 0, 1]
    write_json("inf_matrix.gltf", d)

    def light_doc(light):
        d = base_doc()
        d["extensionsUsed"] = ["KHR_lights_punctual"]
        d["extensions"] = {"KHR_lights_punctual": {"lights": [light]}}
        d["nodes"].append({"extensions": {"KHR_lights_punctual": {"light": 0}}})
        d["scenes"][0]["nodes"] = [0, 1]
        return d
    write_json("nan_light.gltf", light_doc({"type": "point", "intensity": 1e39}))
    write_json("negative_light.gltf", light_doc({"type": "point", "intensity": -5.0}))
    write_json("negative_light_color.gltf", light_doc({"type": "point", "color": [1, -1, 0]}))
    write_json("zero_light_range.gltf", light_doc({"type": "point", "range": 0}))
    write_json(
        "spot_inner_wider_than_outer.gltf",
        light_doc({"type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.8, "outerConeAngle": 0.5}}),
    )

    d = base_doc()
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0, "znear": 0.1}}]
    d["nodes"][0]["camera"] = 0
    write_json("bad_camera.gltf", d)

    write_json("missing_image.gltf", with_texture(base_doc(), {"uri": "missing.png"}))
    gif = b"GIF89a\x01\x00\x01\x00\x00\x00\x00;"
    write_json("unsupported_image.gltf", with_texture(base_doc(), {"uri": data_uri(gif, "image/gif")}))
    write_json("webp_mime.gltf", with_texture(base_doc(), {"uri": data_uri(png(1, 1), "image/webp")}))
    write_json("garbage_image.gltf", with_texture(base_doc(), {"uri": data_uri(b"this is not an image at all", "image/png")}))
    write_json("corrupt_png.gltf", with_texture(base_doc(), {"uri": data_uri(png(4, 4, idat=b"garbage!"), "image/png")}))
    write_json("https_image.gltf", with_texture(base_doc(), {"uri": "https://example.com/texture.png"}))
    # 20000 x 20000 declared in a valid IHDR, with a tiny IDAT: must fail before decoding.
    huge = png(20000, 20000, color_type=2, idat=zlib.compress(b"\0" * 64))
    write_json("huge_texture.gltf", with_texture(base_doc(), {"uri": data_uri(huge, "image/png")}))

    # Over the default LoadOptions budgets, each from a few kilobytes.
    # 1001 nodes x a mesh of 1000 primitives = 1 001 000 instances (limit 1 000 000).
    d = base_doc()
    d["meshes"][0]["primitives"] = d["meshes"][0]["primitives"] * 1000
    d["nodes"] = [{"mesh": 0}] * 1001
    d["scenes"][0]["nodes"] = list(range(1001))
    write_json("too_many_instances.gltf", d)
    # POSITION without a buffer view: 22 369 620 zero-filled vertices (limit 16 000 000).
    d = base_doc()
    del d["accessors"][0]["bufferView"]
    d["accessors"][0]["count"] = 22369620
    write_json("zero_filled_accessor.gltf", d)
    # A chain of 1025 nodes (limit 1024 levels).
    d = base_doc()
    d["nodes"] = [{"children": [i + 1]} for i in range(1024)] + [{"mesh": 0}]
    write_json("deep_node_chain.gltf", d)
    # A buffer declaring a terabyte (limit 1 GiB of buffers): refused before it is read.
    d = base_doc(); d["buffers"][0]["byteLength"] = 1 << 40
    write_json("huge_buffer.gltf", d)

    # Neighbours of files the specification allows: each is refused.
    # A count of 1.5 (a zero fraction, `3.0`, is an integer; 1.5 is not).
    d = base_doc(); d["accessors"][0]["count"] = 1.5
    write_json("fractional_count.gltf", d)
    # A data URI without `;base64` whose percent escape is not two hex digits.
    d = base_doc(); d["buffers"][0]["uri"] = "data:application/octet-stream,%zz" + "%00" * 43
    write_json("bad_percent_data_uri.gltf", d)
    # Buffer 1 has no uri (fine while unused), and the index view reads it.
    d = base_doc(POSITIONS)
    d["buffers"].append({"byteLength": 6})
    d["bufferViews"][1] = {"buffer": 1, "byteLength": 6}
    write_json("uriless_buffer_read.gltf", d)
    # The same in a GLB: only buffer 0 may be the binary chunk.
    d = base_doc()
    d["buffers"] = [{"byteLength": 36}, {"byteLength": 6}]
    d["bufferViews"][1] = {"buffer": 1, "byteLength": 6}
    (HERE / "glb_second_buffer_without_uri.glb").write_bytes(glb(d, POSITIONS))
    # An animation channel without a target (a target without `node` is allowed).
    d = base_doc()
    d["animations"] = [{"samplers": [{"input": 1, "output": 0}], "channels": [{"sampler": 0}]}]
    write_json("animation_without_target.gltf", d)
    # `"scenes": [{}]` is allowed, but the default scene must exist.
    d = base_doc(); d["scenes"] = [{}]; d["scene"] = 1
    write_json("missing_default_scene.gltf", d)
    # KHR_mesh_quantization allows normalized BYTE or SHORT normals, never unsigned ones.
    d = base_doc(POSITIONS + INDICES + bytes([0, 0, 255, 0] * 3))
    d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_mesh_quantization"]
    d["bufferViews"].append({"buffer": 0, "byteOffset": 44, "byteLength": 12, "byteStride": 4})
    d["accessors"].append({"bufferView": 2, "componentType": 5121, "normalized": True, "count": 3,
                           "type": "VEC3"})
    d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2
    write_json("quantized_unsigned_normal.gltf", d)


if __name__ == "__main__":
    main()
