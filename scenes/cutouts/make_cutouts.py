#!/usr/bin/env python3
"""Generates the cut-out assets of scenes/cutouts.json (made by the sahara project).

    python3 scenes/cutouts/make_cutouts.py      # rewrites the files next to this script

- bush.obj / bush.mtl: a bush of leaf cards (quads) whose material cuts the
  leaves out with `map_d leaf.png` (the PNG's alpha channel); OBJ d / map_d
  is stochastic transparency in sahara.
- leaf.png: a sprig of leaves, RGBA, alpha 0 between the leaves.
- fence.gltf: a trellis fence panel with alphaMode MASK (alphaCutoff 0.5) over
  fence.png; the buffer is embedded as a data: URI.
- fence.png: the trellis, RGBA, alpha 0 in the holes.

Only the Python standard library is used (PNG via zlib), and the output is
deterministic (fixed random seed), so re-running it reproduces the files.
"""
import base64
import math
import os
import random
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def write_png(path, width, height, pixels):
    """pixels: rows (top first) of (r, g, b, a) tuples with 0-255 components."""
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in pixels)

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)  # 8-bit RGBA
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9)) +
                chunk(b"IEND", b""))


def leaf_image(size=256):
    """A sprig: a stem up the middle of the card and alternate elliptical leaves."""
    # Leaves: (base x, base y, angle from vertical, length, half-width), card coordinates in [0, 1].
    leaves = []
    for i in range(7):
        y = 0.12 + 0.12 * i
        side = -1 if i % 2 else 1
        leaves.append((0.5, y, side * (0.95 - 0.06 * i), 0.34 - 0.02 * i, 0.085 - 0.004 * i))
    leaves.append((0.5, 0.9, 0.0, 0.1, 0.05))  # the tip
    rows = []
    for py in range(size):
        row = []
        for px in range(size):
            x, y = (px + 0.5) / size, 1.0 - (py + 0.5) / size  # y up
            alpha, shade, vein = 0, 0.0, False
            if abs(x - 0.5) < 0.012 and 0.02 < y < 0.92:  # stem
                alpha, shade = 255, 0.55
            for bx, by, ang, length, half in leaves:
                # Leaf frame: along (sin ang, cos ang) from the base.
                dx, dy = x - bx, y - by
                along = dx * math.sin(ang) + dy * math.cos(ang)
                across = dx * math.cos(ang) - dy * math.sin(ang)
                t = along / length
                if 0.0 < t < 1.0:
                    w = half * math.sin(math.pi * t) ** 0.8
                    if abs(across) < w:
                        alpha = 255
                        shade = 0.75 + 0.25 * (across / w) + 0.1 * t
                        vein = abs(across) < 0.006
            if alpha:
                g = min(1.0, shade)
                r, gg, b = (0.18 * g, 0.55 * g, 0.12 * g) if not vein else (0.45, 0.65, 0.25)
                row.append((int(255 * r), int(255 * gg), int(255 * b), 255))
            else:
                row.append((40, 90, 30, 0))  # colour under alpha 0: dark green, never seen
        rows.append(row)
    return size, size, rows


def fence_image(size=128):
    """A diagonal trellis: two sets of slats crossing at right angles, with a frame."""
    rows = []
    period, slat = 0.25, 0.045
    for py in range(size):
        row = []
        for px in range(size):
            x, y = (px + 0.5) / size, (py + 0.5) / size
            a = (x + y) % period
            b = (x - y) % period
            on = a < slat or b < slat or y < 0.06 or y > 0.94
            grain = 0.85 + 0.15 * math.sin(40.0 * (x + y if a < slat else x - y))
            if on:
                row.append((int(200 * grain), int(170 * grain), int(120 * grain), 255))
            else:
                row.append((120, 100, 70, 0))
        rows.append(row)
    return size, size, rows


def bush_cards(rng, count=40):
    """Leaf cards (4 corners each) around a vertical axis: yaw, tilt and height vary."""
    cards = []
    for i in range(count):
        yaw = 2 * math.pi * (i / count) + rng.uniform(-0.3, 0.3)
        tilt = rng.uniform(0.25, 0.85)  # from vertical, leaning outwards
        h0 = rng.uniform(0.0, 0.35)
        length, width = rng.uniform(0.9, 1.3), rng.uniform(0.5, 0.7)
        out = (math.cos(yaw), math.sin(yaw))
        side = (-math.sin(yaw), math.cos(yaw))
        up = (out[0] * math.sin(tilt), out[1] * math.sin(tilt), math.cos(tilt))
        base = (0.05 * out[0], 0.05 * out[1], h0)
        hw = 0.5 * width
        p0 = (base[0] - hw * side[0], base[1] - hw * side[1], base[2])
        p1 = (base[0] + hw * side[0], base[1] + hw * side[1], base[2])
        p2 = tuple(p1[k] + length * up[k] for k in range(3))
        p3 = tuple(p0[k] + length * up[k] for k in range(3))
        cards.append((p0, p1, p2, p3))
    return cards


def write_bush():
    rng = random.Random(20261122)
    cards = bush_cards(rng)
    with open(os.path.join(HERE, "bush.mtl"), "w") as f:
        f.write("# Leaf cards cut out by the alpha of leaf.png (made by the sahara project).\n")
        f.write("newmtl leaves\nKd 1 1 1\nmap_Kd leaf.png\nmap_d leaf.png\n")
    with open(os.path.join(HERE, "bush.obj"), "w") as f:
        f.write("# A bush of %d leaf cards, generated by make_cutouts.py (sahara project).\n" % len(cards))
        f.write("mtllib bush.mtl\no bush\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl leaves\n")
        for c in cards:
            for p in c:
                f.write("v %.4f %.4f %.4f\n" % p)
        for i in range(len(cards)):
            v = 4 * i + 1
            f.write("f %d/1 %d/2 %d/3 %d/4\n" % (v, v + 1, v + 2, v + 3))


def write_fence():
    # One panel 4 wide (x) and 1.5 tall (z), standing on z = 0; the trellis repeats 3 times.
    pos = [0, 0, 0, 4, 0, 0, 4, 0, 1.5, 0, 0, 1.5]
    uv = [0, 1, 3, 1, 3, 0, 0, 0]  # glTF: v = 0 at the image top
    nrm = [0, -1, 0] * 4
    idx = [0, 1, 2, 0, 2, 3]
    data = struct.pack("<12f", *pos) + struct.pack("<8f", *uv) + struct.pack("<12f", *nrm) + \
        struct.pack("<6H", *idx) + b"\x00\x00"
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    gltf = """{
  "asset": {"version": "2.0", "generator": "sahara scenes/cutouts/make_cutouts.py"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "name": "fence"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "NORMAL": 2}, "indices": 3,
                              "material": 0}]}],
  "materials": [{"name": "trellis", "doubleSided": true, "alphaMode": "MASK", "alphaCutoff": 0.5,
                 "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
  "textures": [{"source": 0, "sampler": 0}],
  "samplers": [{"wrapS": 10497, "wrapT": 33071}],
  "images": [{"uri": "fence.png"}],
  "buffers": [{"byteLength": %d, "uri": "%s"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 128, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [0, 0, 0], "max": [4, 0, 1.5]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
}
""" % (len(data), uri)
    with open(os.path.join(HERE, "fence.gltf"), "w") as f:
        f.write(gltf)


def main():
    write_png(os.path.join(HERE, "leaf.png"), *leaf_image())
    write_png(os.path.join(HERE, "fence.png"), *fence_image())
    write_bush()
    write_fence()


if __name__ == "__main__":
    main()
