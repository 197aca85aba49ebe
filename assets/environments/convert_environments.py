#!/usr/bin/env python3
"""Writes studio_small_03.hdr and venice_sunset.hdr from Poly Haven's 1k Radiance files.

Usage: convert_environments.py SRC_DIR
SRC_DIR holds studio_small_03_1k.hdr and venice_sunset_1k.hdr, byte-identical to
pmndrs/drei-assets@456060a26bbeb8fdf79326f224b6d99b8bcce736 hdri/ (Poly Haven's 1k
downloads; the SHA-256 sums are checked). Both are 1024x512 equirectangular.

- venice_sunset.hdr: the same 1024x512 RGBE texels, written again with a plain header.
- studio_small_03.hdr: decoded to linear float (value = mantissa * 2^(exponent - 136), the
  convention of stb_image and the `image` crate), box-filtered 2x2 to 512x256, encoded again.

Output: Radiance RGBE with the new run-length encoding, rows top to bottom ("-Y H +X W").
Run with python3, no dependencies.
"""
import hashlib, math, os, sys

HERE = os.path.dirname(os.path.abspath(__file__))

# (source file, SHA-256 of the source, output file, number of 2x2 box halvings)
JOBS = [
    ("studio_small_03_1k.hdr", "29267a4aa8c10de26cae758e4e3c4daadde88673798666ad657724bab7224a35", "studio_small_03.hdr", 1),
    ("venice_sunset_1k.hdr", "0e72ed46b5316cb5fb67fc81ff85b024a09146fd89ef3811a8d2299647ada118", "venice_sunset.hdr", 0),
]


def read_hdr(data):
    """Decodes a new-RLE Radiance file: (width, height, RGBE bytes, rows top to bottom)."""
    pos = 0
    lines = []
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii", "replace")
        pos = end + 1
        if line == "":
            break
        lines.append(line)
    assert lines[0].startswith("#?") and "FORMAT=32-bit_rle_rgbe" in lines, lines
    end = data.index(b"\n", pos)
    res = data[pos:end].decode("ascii").split()
    pos = end + 1
    assert res[0] == "-Y" and res[2] == "+X", res
    h, w = int(res[1]), int(res[3])
    out = bytearray(w * h * 4)
    for y in range(h):
        assert data[pos] == 2 and data[pos + 1] == 2 and (data[pos + 2] << 8 | data[pos + 3]) == w, y
        pos += 4
        base = y * w * 4
        for c in range(4):
            x = 0
            while x < w:
                n = data[pos]
                pos += 1
                if n > 128:
                    n -= 128
                    v = data[pos]
                    pos += 1
                    for i in range(n):
                        out[base + (x + i) * 4 + c] = v
                else:
                    for i in range(n):
                        out[base + (x + i) * 4 + c] = data[pos + i]
                    pos += n
                x += n
            assert x == w, y
    assert pos == len(data)
    return w, h, bytes(out)


def to_float(px):
    f = []
    for i in range(0, len(px), 4):
        r, g, b, e = px[i:i + 4]
        s = math.ldexp(1.0, e - 136) if e else 0.0
        f.append((r * s, g * s, b * s))
    return f


def to_rgbe(f):
    out = bytearray()
    for r, g, b in f:
        m = max(r, g, b)
        if not m > 1e-32:
            out += b"\0\0\0\0"
            continue
        frac, ex = math.frexp(m)
        s = frac * 256.0 / m
        out += bytes((min(255, int(r * s)), min(255, int(g * s)), min(255, int(b * s)), ex + 128))
    return bytes(out)


def box2(w, h, f):
    """Averages each 2x2 block of linear values."""
    out = []
    for y in range(h // 2):
        for x in range(w // 2):
            q = (f[2 * y * w + 2 * x], f[2 * y * w + 2 * x + 1], f[(2 * y + 1) * w + 2 * x], f[(2 * y + 1) * w + 2 * x + 1])
            out.append(tuple(sum(p[k] for p in q) * 0.25 for k in range(3)))
    return w // 2, h // 2, out


def rle(vals):
    out = bytearray()
    i, n = 0, len(vals)
    while i < n:
        j = i
        while j < n and j - i < 127 and vals[j] == vals[i]:
            j += 1
        if j - i >= 3:
            out += bytes((128 + j - i, vals[i]))
            i = j
            continue
        k = i
        while k < n and k - i < 128 and not (k + 2 < n and vals[k] == vals[k + 1] == vals[k + 2]):
            k += 1
        out.append(k - i)
        out += vals[i:k]
        i = k
    return out


def write_hdr(path, w, h, px):
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += b"-Y %d +X %d\n" % (h, w)
    for y in range(h):
        row = px[y * w * 4:(y + 1) * w * 4]
        out += bytes((2, 2, w >> 8, w & 0xFF))
        for c in range(4):
            out += rle(row[c::4])
    with open(path, "wb") as fh:
        fh.write(out)


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "."
    for name, sha, dst, halvings in JOBS:
        data = open(os.path.join(src, name), "rb").read()
        assert hashlib.sha256(data).hexdigest() == sha, f"{name}: unexpected SHA-256"
        w, h, px = read_hdr(data)
        if halvings:
            f = to_float(px)
            for _ in range(halvings):
                w, h, f = box2(w, h, f)
            px = to_rgbe(f)
        write_hdr(os.path.join(HERE, dst), w, h, px)
        print(f"{dst}: {w}x{h}")


if __name__ == "__main__":
    main()
