#!/usr/bin/env python3
"""Writes a generated interior (an OBJ and a scene JSON beside it) for the
interior benchmarks of docs/performance.md: long thin walls, floors and beams
around many small objects, the case where top-down BVH builds struggle.

Kinds:
  hall    one long room: windows in one long wall, two rows of columns, rows of
          chairs, shelves of books along the end walls, ceiling beams
  office  an open-plan floor: a mullioned window band on all sides, desks with
          monitors and chairs in blocks separated by partitions, columns,
          ceiling light panels
  flat    several rooms behind interior walls with door openings: beds, sofas,
          tables with chairs, kitchen cabinets, bookshelves

Usage: generate_interior.py OUT_DIR [--kind hall] [--seed 1] [--size 24 8 5]
           [--windows 6] [--columns 12] [--chairs 300] [--books 1600] [--desks 0]
           [--rooms 0]
then:  sahara bench OUT_DIR/KIND.json --json --threads 2 --size 512 --builder reinsert
The same arguments always give the same files (Python's random with the seed).
"""
import argparse
import json
import math
import os
import random


class Mesh:
    """Triangles as OBJ text; every solid is an axis-aligned box or a prism."""

    def __init__(self):
        self.vertices = []
        self.faces = []

    def box(self, x0, y0, z0, x1, y1, z1):
        if x1 - x0 <= 0 or y1 - y0 <= 0 or z1 - z0 <= 0:
            return
        base = len(self.vertices) + 1
        for z in (z0, z1):
            for y in (y0, y1):
                for x in (x0, x1):
                    self.vertices.append((x, y, z))
        # corners: index = x + 2y + 4z; quads wound outwards
        quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        for a, b, c, d in quads:
            self.faces.append((base + a, base + b, base + c))
            self.faces.append((base + a, base + c, base + d))

    def cylinder(self, cx, cy, z0, z1, radius, segments=12):
        """A vertical prism of `segments` sides, capped."""
        base = len(self.vertices) + 1
        for z in (z0, z1):
            for k in range(segments):
                phi = 2 * math.pi * k / segments
                self.vertices.append((cx + radius * math.cos(phi), cy + radius * math.sin(phi), z))
        self.vertices.append((cx, cy, z0))
        self.vertices.append((cx, cy, z1))
        bottom, top = base + 2 * segments, base + 2 * segments + 1
        for k in range(segments):
            a, b = base + k, base + (k + 1) % segments
            c, d = a + segments, b + segments
            self.faces.append((a, b, d))
            self.faces.append((a, d, c))
            self.faces.append((bottom, b, a))
            self.faces.append((top, c, d))

    def write(self, path, comment):
        with open(path, "w") as f:
            f.write(f"# {comment}\n")
            for x, y, z in self.vertices:
                f.write(f"v {x:.5g} {y:.5g} {z:.5g}\n")
            for a, b, c in self.faces:
                f.write(f"f {a} {b} {c}\n")


def shell(m, length, width, height, t=0.3):
    """Floor and ceiling slabs and the two short walls (the long walls carry windows)."""
    m.box(-t, -t, -t, length + t, width + t, 0)
    m.box(-t, -t, height, length + t, width + t, height + t)
    m.box(-t, 0, 0, 0, width, height)
    m.box(length, 0, 0, length + t, width, height)


def wall_with_windows(m, length, y0, y1, height, windows, sill, lintel, mullions=0):
    """A wall along x from y0 to y1 with `windows` equal openings from sill to lintel."""
    if windows == 0:
        m.box(0, y0, 0, length, y1, height)
        return
    pier = length / (2 * windows + 1)
    m.box(0, y0, 0, length, y1, sill)
    m.box(0, y0, lintel, length, y1, height)
    for k in range(windows + 1):
        x = (2 * k) * pier
        m.box(x, y0, sill, x + pier, y1, lintel)
        if k < windows:
            for j in range(1, mullions + 1):  # thin vertical bars across the opening
                xm = x + pier + pier * j / (mullions + 1)
                m.box(xm - 0.02, y0, sill, xm + 0.02, y1, lintel)


def chair(m, x, y, turn):
    """Seat, back and four legs (six boxes); the back on the side given by `turn`."""
    s = 0.22
    for dx in (-s + 0.02, s - 0.02):
        for dy in (-s + 0.02, s - 0.02):
            m.box(x + dx - 0.02, y + dy - 0.02, 0, x + dx + 0.02, y + dy + 0.02, 0.45)
    m.box(x - s, y - s, 0.45, x + s, y + s, 0.5)
    by = y + s if turn else y - s - 0.04
    m.box(x - s, by, 0.5, x + s, by + 0.04, 0.95)


def shelf_of_books(m, rng, x0, x1, y0, depth, z0, rows, count, along_x=True):
    """A shelf unit (boards) filled with `count` books of random sizes."""
    height = 0.4 * rows
    for r in range(rows + 1):
        z = z0 + 0.4 * r
        if along_x:
            m.box(x0, y0, z, x1, y0 + depth, z + 0.02)
        else:
            m.box(y0, x0, z, y0 + depth, x1, z + 0.02)
    placed, row, pos = 0, 0, x0
    while placed < count and row < rows:
        w = rng.uniform(0.02, 0.06)
        h = rng.uniform(0.2, 0.36)
        d = rng.uniform(0.14, depth - 0.02)
        if pos + w > x1:
            row, pos = row + 1, x0
            continue
        z = z0 + 0.4 * row + 0.02
        if along_x:
            m.box(pos, y0, z, pos + w, y0 + d, z + h)
        else:
            m.box(y0, pos, z, y0 + d, pos + w, z + h)
        pos += w + rng.uniform(0.0, 0.01)
        placed += 1
    return placed, height


def books_along(m, rng, count, length, y0, depth, z0, max_rows, along_x=True):
    """Books on shelf units side by side until `count` are placed."""
    placed, x = 0, 0.3
    while placed < count and x + 1.2 <= length - 0.3:
        n, _ = shelf_of_books(m, rng, x, x + 1.2, y0, depth, z0, max_rows, count - placed, along_x)
        placed += n
        x += 1.3
    return placed


def hall(m, rng, a):
    length, width, height = a.size
    shell(m, length, width, height)
    wall_with_windows(m, length, -0.3, 0, height, 0, 0, 0)
    wall_with_windows(m, length, width, width + 0.3, height, a.windows, 1.2, height - 1.2)
    for k in range(a.columns):  # two rows
        row, i = k % 2, k // 2
        per_row = (a.columns + 1) // 2
        x = length * (i + 1) / (per_row + 1)
        m.cylinder(x, width * (0.25 if row == 0 else 0.75), 0, height, 0.25, 16)
    for i in range(int(length // 3)):  # ceiling beams across the room
        x = 1.5 + 3 * i
        m.box(x - 0.1, 0, height - 0.4, x + 0.1, width, height)
    per_row = max(1, int((length - 4) / 0.6))
    for k in range(a.chairs):
        row, i = k // per_row, k % per_row
        x = 2 + 0.6 * i + rng.uniform(-0.05, 0.05)
        y = 1.5 + 0.9 * row + rng.uniform(-0.05, 0.05)
        if y > width - 1:
            break
        chair(m, x, y, True)
    half = a.books // 2
    books_along(m, rng, half, width, 0.02, 0.3, 0.1, 8, along_x=False)
    books_along(m, rng, a.books - half, width, length - 0.32, 0.3, 0.1, 8, along_x=False)
    camera = {"position": [length - 2, 1.5, 2.2], "look_at": [length / 3, width * 0.75, 1.2], "up": [0, 0, 1], "vfov": 62}
    return camera, [-0.3, -1.0, -0.6]


def desk(m, x, y, facing):
    m.box(x - 0.8, y - 0.4, 0.72, x + 0.8, y + 0.4, 0.75)
    for dx in (-0.75, 0.73):
        m.box(x + dx, y - 0.38, 0, x + dx + 0.02, y + 0.38, 0.72)
    my = y + 0.25 * facing
    m.box(x - 0.3, my - 0.02, 0.85, x + 0.3, my + 0.02, 1.2)  # monitor
    m.box(x - 0.03, my - 0.03, 0.75, x + 0.03, my + 0.03, 0.85)
    m.box(x - 0.25, y - 0.15 * facing - 0.08, 0.75, x + 0.25, y - 0.15 * facing + 0.08, 0.77)  # keyboard


def office(m, rng, a):
    length, width, height = a.size
    m.box(-0.3, -0.3, -0.3, length + 0.3, width + 0.3, 0)
    m.box(-0.3, -0.3, height, length + 0.3, width + 0.3, height + 0.3)
    wall_with_windows(m, length, -0.3, 0, height, a.windows, 0.9, height - 0.4, mullions=2)
    wall_with_windows(m, length, width, width + 0.3, height, a.windows, 0.9, height - 0.4, mullions=2)
    m.box(-0.3, 0, 0, 0, width, height)
    m.box(length, 0, 0, length + 0.3, width, height)
    per_row = (a.columns + 1) // 2
    for k in range(a.columns):
        x = length * (k // 2 + 1) / (per_row + 1)
        y = width * (1 / 3 if k % 2 == 0 else 2 / 3)
        m.box(x - 0.3, y - 0.3, 0, x + 0.3, y + 0.3, height)
    for i in range(int(length // 2.4)):  # ceiling light panels
        for j in range(int(width // 2.4)):
            x, y = 1.2 + 2.4 * i, 1.2 + 2.4 * j
            m.box(x - 0.6, y - 0.3, height - 0.05, x + 0.6, y + 0.3, height)
    # desk blocks: pairs of facing desks, partitions between the pairs' rows
    per_block_row = max(1, int((length - 2) / 1.7))
    for k in range(a.desks):
        pair, i = k // (2 * per_block_row), (k // 2) % per_block_row
        x = 1.2 + 1.7 * i
        y0 = 1.8 + 3.4 * pair
        if y0 + 1.0 > width - 1:
            break
        facing = 1 if k % 2 == 0 else -1
        y = y0 + (0.45 if facing == 1 else 1.45)
        desk(m, x, y, facing)
        chair(m, x + rng.uniform(-0.1, 0.1), y - 0.75 * facing, facing == -1)
        if k % 2 == 0:  # a partition panel between the facing desks
            m.box(x - 0.85, y0 + 0.93, 0, x + 0.85, y0 + 0.97, 1.35)
    placed = 0
    x = 0.5
    while placed < a.books and x < length - 1.5:  # low cabinets with binders along the walls
        n, _ = shelf_of_books(m, rng, x, x + 1.2, 0.05, 0.35, 0.0, 2, a.books - placed)
        placed += n
        x += 1.6
    camera = {"position": [1.0, width * 0.5, 1.7], "look_at": [length * 0.6, width * 0.3, 1.0], "up": [0, 0, 1], "vfov": 65}
    return camera, [0.4, 1.0, -0.55]


def flat(m, rng, a):
    length, width, height = a.size
    shell(m, length, width, height)
    wall_with_windows(m, length, -0.25, 0, height, a.windows, 0.9, height - 0.3)
    wall_with_windows(m, length, width, width + 0.25, height, 0, 0, 0)
    rooms = max(1, a.rooms)
    room_len = length / rooms
    corridor = 1.2
    for r in range(1, rooms):  # walls between rooms, each with a door near the corridor
        x = r * room_len
        m.box(x - 0.06, 0, 0, x + 0.06, width - corridor - 1.0, height)
        m.box(x - 0.06, width - corridor - 1.0, 2.1, x + 0.06, width - corridor, height)
    for r in range(rooms):  # the corridor wall with one door per room
        x0, x1 = r * room_len, (r + 1) * room_len
        door = x0 + room_len * 0.5
        yc = width - corridor
        m.box(x0, yc - 0.06, 0, door - 0.45, yc + 0.06, height)
        m.box(door + 0.45, yc - 0.06, 0, x1, yc + 0.06, height)
        m.box(door - 0.45, yc - 0.06, 2.1, door + 0.45, yc + 0.06, height)
        furnish_room(m, rng, r, x0 + 0.2, x1 - 0.2, 0.2, yc - 0.2, a)
    camera = {"position": [room_len * 0.5, 0.6, 1.6], "look_at": [room_len * 0.5 + 1, width - 1.0, 1.1], "up": [0, 0, 1], "vfov": 70}
    return camera, [0.3, 1.0, -0.6]


def furnish_room(m, rng, r, x0, x1, y0, y1, a):
    kind = r % 3
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    if kind == 0:  # living room: sofa, low table, shelves of books
        m.box(x0, y1 - 0.9, 0, x0 + 2.2, y1, 0.45)
        m.box(x0, y1 - 0.2, 0.45, x0 + 2.2, y1, 0.85)
        m.box(cx - 0.6, cy - 0.3, 0.35, cx + 0.6, cy + 0.3, 0.4)
        books_along(m, rng, a.books // max(1, a.rooms), min(x1 - x0, 4.0) + 0.6, y0, 0.3, 0.05, 5)
    elif kind == 1:  # bedroom: bed, wardrobe, bedside lamp
        m.box(cx - 0.8, y0, 0, cx + 0.8, y0 + 2.0, 0.5)
        m.box(cx - 0.8, y0, 0.5, cx + 0.8, y0 + 0.08, 1.1)
        m.box(x1 - 0.6, y0, 0, x1, y0 + 1.8, 2.2)
        m.cylinder(cx + 1.2, y0 + 0.3, 0, 1.4, 0.012, 8)
        m.cylinder(cx + 1.2, y0 + 0.3, 1.4, 1.6, 0.15, 16)
    else:  # kitchen: cabinet run, table and chairs
        m.box(x0, y0, 0, x1, y0 + 0.6, 0.9)
        m.box(x0, y0, 1.5, x1, y0 + 0.35, 2.2)
        m.box(cx - 0.7, cy - 0.45, 0.72, cx + 0.7, cy + 0.45, 0.76)
        for dx in (-0.65, 0.63):
            for dy in (-0.4, 0.38):
                m.box(cx + dx, cy + dy, 0, cx + dx + 0.02, cy + dy + 0.02, 0.72)
    chairs = a.chairs // max(1, a.rooms)
    for k in range(chairs):  # loose chairs around the room
        x = rng.uniform(x0 + 0.3, x1 - 0.3)
        y = rng.uniform(y0 + 0.3, y1 - 0.3)
        chair(m, x, y, rng.random() < 0.5)


PRESETS = {
    "hall": dict(size=[24, 8, 5], windows=6, columns=12, chairs=300, books=1600, desks=0, rooms=0),
    "office": dict(size=[30, 16, 3.2], windows=10, columns=8, chairs=0, books=600, desks=96, rooms=0),
    "flat": dict(size=[24, 10, 2.7], windows=7, columns=0, chairs=80, books=2400, desks=0, rooms=8),
}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out_dir")
    p.add_argument("--kind", choices=sorted(PRESETS), default="hall")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--size", type=float, nargs=3, metavar=("LENGTH", "WIDTH", "HEIGHT"))
    for name in ("windows", "columns", "chairs", "books", "desks", "rooms"):
        p.add_argument("--" + name, type=int)
    a = p.parse_args()
    for key, value in PRESETS[a.kind].items():
        if getattr(a, key) is None:
            setattr(a, key, value)
    rng = random.Random(a.seed)
    m = Mesh()
    camera, sun = {"hall": hall, "office": office, "flat": flat}[a.kind](m, rng, a)
    os.makedirs(a.out_dir, exist_ok=True)
    m.write(os.path.join(a.out_dir, a.kind + ".obj"),
            f"generated by bench/generate_interior.py --kind {a.kind} --seed {a.seed}")
    scene = {
        "format": "scene/1",
        "render": {"width": 640, "height": 400, "spp": 64, "max_depth": 6},
        "camera": camera,
        "background": {"type": "gradient", "bottom": [1.6, 1.6, 1.5], "top": [0.6, 0.9, 1.8], "up": [0, 0, 1]},
        "objects": [{"type": "mesh", "file": a.kind + ".obj"}],
        "lights": [{"type": "directional", "direction": sun, "irradiance": [4.0, 3.7, 3.2]}],
    }
    with open(os.path.join(a.out_dir, a.kind + ".json"), "w") as f:
        json.dump(scene, f, indent=2)
    print(f"{a.kind}: {len(m.faces)} triangles -> {a.out_dir}")


if __name__ == "__main__":
    main()
