#!/usr/bin/env python3
"""Generates scenes/interior/room.obj and room.mtl, the geometry of scenes/interior.json
(made by the sahara project).

    python3 scenes/interior/make_interior.py    # rewrites the files next to this script
    build/sahara render scenes/interior.json --size 480x300 --spp 256 -o scenes/images/interior.png

A furnished room of the kind architectural models hold, made to be seen from
inside: walls with three windows, a tall window and a door (open, the leaf
swung back), a plank floor, ceiling beams, two turned columns, a table with six
chairs, a bookcase full of books, a floor lamp and a bowl; the ground outside.
Walls, planks, beams and shelves are long thin boxes (long thin triangles,
boxes full of empty space around them); the turned legs, columns, lamp and
bowl are lathe surfaces with many small triangles. Z is up, units are metres,
the room's inside spans x 0..8, y 0..6, z 0..3.

Only the Python standard library is used, and the output is deterministic
(fixed random seed), so re-running it reproduces the files.
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))

MATERIALS = {
    "plaster": (0.78, 0.75, 0.70),
    "ceiling": (0.85, 0.85, 0.83),
    "floor": (0.50, 0.34, 0.20),
    "beam": (0.33, 0.21, 0.12),
    "stone": (0.70, 0.68, 0.62),
    "frame": (0.88, 0.88, 0.86),
    "oak": (0.55, 0.38, 0.22),
    "walnut": (0.30, 0.19, 0.11),
    "book_red": (0.55, 0.12, 0.10),
    "book_blue": (0.12, 0.20, 0.45),
    "book_green": (0.15, 0.35, 0.18),
    "book_ochre": (0.70, 0.52, 0.20),
    "book_cream": (0.82, 0.78, 0.66),
    "shade": (0.90, 0.86, 0.75),
    "iron": (0.12, 0.12, 0.12),
    "ceramic": (0.25, 0.42, 0.55),
    "rug": (0.55, 0.20, 0.15),
    "ground": (0.35, 0.40, 0.25),
}


class Mesh:
    """Vertices and triangles grouped by material, with a current placement (rotation about
    z, then translation) applied to every point added."""

    def __init__(self):
        self.vertices = []
        self.faces = {name: [] for name in MATERIALS}
        self.place(0.0, 0.0, 0.0, 0.0)

    def place(self, x, y, z, angle_deg):
        self.origin = (x, y, z)
        a = math.radians(angle_deg)
        self.cos, self.sin = math.cos(a), math.sin(a)

    def vertex(self, p):
        x, y, z = p
        ox, oy, oz = self.origin
        self.vertices.append((ox + self.cos * x - self.sin * y, oy + self.sin * x + self.cos * y, oz + z))
        return len(self.vertices)  # OBJ indices start at 1

    def tri(self, material, a, b, c):
        self.faces[material].append((a, b, c))

    def box(self, material, lo, hi):
        """An axis-aligned box (in the current placement's frame), 12 triangles, faces outward."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        v = [self.vertex((x, y, z)) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
        for a, b, c, d in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
            self.tri(material, v[a], v[b], v[c])
            self.tri(material, v[a], v[c], v[d])

    def lathe(self, material, profile, segments, cx=0.0, cy=0.0, z0=0.0):
        """A surface of revolution about the vertical through (cx, cy): profile is (radius, z)
        from bottom to top; ends with radius > 0 are closed by fans."""
        rings = []
        for r, z in profile:
            if r <= 0:  # a pole: one vertex, so no zero-area triangles
                rings.append([self.vertex((cx, cy, z0 + z))] * segments)
                continue
            rings.append([self.vertex((cx + r * math.cos(2 * math.pi * k / segments),
                                       cy + r * math.sin(2 * math.pi * k / segments), z0 + z))
                          for k in range(segments)])
        for lower, upper in zip(rings, rings[1:]):
            for k in range(segments):
                k1 = (k + 1) % segments
                if lower[k] != lower[k1]:
                    self.tri(material, lower[k], lower[k1], upper[k1])
                if upper[k] != upper[k1]:
                    self.tri(material, lower[k], upper[k1], upper[k])
        for ring, (r, z), up in ((rings[0], profile[0], False), (rings[-1], profile[-1], True)):
            if r <= 0:
                continue
            centre = self.vertex((cx, cy, z0 + z))
            for k in range(segments):
                k1 = (k + 1) % segments
                if up:
                    self.tri(material, centre, ring[k], ring[k1])
                else:
                    self.tri(material, centre, ring[k1], ring[k])


def turned_profile(radius, height, beads, steps_per_bead=6):
    """A turned leg or baluster: a slim shaft with `beads` rounded swellings."""
    profile = []
    n = beads * steps_per_bead
    for i in range(n + 1):
        t = i / n
        bulge = 0.35 * math.sin(math.pi * (t * beads % 1.0)) ** 2
        taper = 1.0 - 0.25 * t
        profile.append((radius * taper * (0.75 + bulge), height * t))
    return profile


def wall_x(m, y0, y1, openings, x0=-0.25, x1=8.25, height=3.0):
    """A wall along x (from x0 to x1, thickness y0..y1) with openings (xa, xb, za, zb)."""
    x = x0
    for xa, xb, za, zb in sorted(openings):
        m.box("plaster", (x, y0, 0.0), (xa, y1, height))
        if za > 0.0:
            m.box("plaster", (xa, y0, 0.0), (xb, y1, za))
        m.box("plaster", (xa, y0, zb), (xb, y1, height))
        x = xb
    m.box("plaster", (x, y0, 0.0), (x1, y1, height))


def window_frame(m, xa, xb, za, zb, y0, y1, mullions=2, transoms=1):
    """A frame lining the opening and thin glazing bars (no glass: the opening stays open)."""
    f = 0.06
    m.box("frame", (xa, y0, za), (xb, y1, za + f))
    m.box("frame", (xa, y0, zb - f), (xb, y1, zb))
    m.box("frame", (xa, y0, za), (xa + f, y1, zb))
    m.box("frame", (xb - f, y0, za), (xb, y1, zb))
    ym = 0.5 * (y0 + y1)
    for i in range(1, mullions + 1):
        x = xa + (xb - xa) * i / (mullions + 1)
        m.box("frame", (x - 0.02, ym - 0.02, za), (x + 0.02, ym + 0.02, zb))
    for i in range(1, transoms + 1):
        z = za + (zb - za) * i / (transoms + 1)
        m.box("frame", (xa, ym - 0.02, z - 0.02), (xb, ym + 0.02, z + 0.02))


def shell(m):
    """Floor, ceiling, walls with their openings, frames, beams, baseboards, ground outside."""
    m.box("ground", (-30.0, -30.0, -0.3), (38.0, 36.0, -0.2))
    m.box("plaster", (-0.25, -0.25, -0.2), (8.25, 6.25, 0.0))  # slab under the planks
    plank = 0.18
    for i in range(int(6.0 / plank)):
        m.box("floor", (0.0, i * plank + 0.002, 0.0), (8.0, (i + 1) * plank - 0.002, 0.02))
    m.box("ceiling", (-0.25, -0.25, 3.0), (8.25, 6.25, 3.2))
    south = [(x - 0.7, x + 0.7, 0.8, 2.4) for x in (1.5, 4.0, 6.5)]
    wall_x(m, -0.25, 0.0, south)
    for xa, xb, za, zb in south:
        window_frame(m, xa, xb, za, zb, -0.25, 0.0)
    wall_x(m, 6.0, 6.25, [])
    # West and east walls run along y: built as x-walls in a frame turned by 90 degrees.
    m.place(0.0, 0.0, 0.0, 90.0)  # local x -> world y, local y -> world -x
    wall_x(m, 0.0, 0.25, [(2.0, 4.0, 0.5, 2.6)], x0=0.0, x1=6.0)
    window_frame(m, 2.0, 4.0, 0.5, 2.6, 0.0, 0.25, mullions=3, transoms=2)
    wall_x(m, -8.25, -8.0, [(4.0, 5.0, 0.0, 2.2)], x0=0.0, x1=6.0)
    m.box("frame", (3.94, -8.25, 0.0), (4.0, -8.0, 2.26))
    m.box("frame", (5.0, -8.25, 0.0), (5.06, -8.0, 2.26))
    m.box("frame", (3.94, -8.25, 2.2), (5.06, -8.0, 2.26))
    m.place(0.0, 0.0, 0.0, 0.0)
    m.box("walnut", (7.0, 4.0, 0.0), (7.96, 4.04, 2.18))  # the door leaf, swung into the room
    for x in range(1, 8):
        m.box("beam", (x - 0.1, 0.0, 2.7), (x + 0.1, 6.0, 3.0))
    m.box("beam", (0.0, 2.9, 2.55), (8.0, 3.1, 2.7))  # a girder under the beams
    for y0, y1 in ((0.0, 0.015), (5.985, 6.0)):
        m.box("walnut", (0.0, y0, 0.0), (8.0, y1, 0.1))
    for x0, x1 in ((0.0, 0.015), (7.985, 8.0)):
        m.box("walnut", (x0, 0.0, 0.0), (x1, 6.0, 0.1))


def column(m, x, y):
    """A column with a moulded base and capital, fluted shaft (48 segments)."""
    profile = [(0.28, 0.0), (0.28, 0.08), (0.24, 0.1), (0.24, 0.16), (0.21, 0.2)]
    for i in range(1, 24):
        profile.append((0.18 - 0.02 * i / 24, 0.2 + 2.2 * i / 24))
    profile += [(0.18, 2.45), (0.22, 2.5), (0.26, 2.52), (0.26, 2.55), (0.0, 2.55)]
    m.lathe("stone", profile, 48, x, y)


def table(m, x, y):
    m.place(x, y, 0.0, 0.0)
    m.box("oak", (-1.0, -0.5, 0.72), (1.0, 0.5, 0.77))
    m.box("oak", (-0.9, -0.42, 0.64), (0.9, -0.4, 0.72))  # aprons
    m.box("oak", (-0.9, 0.4, 0.64), (0.9, 0.42, 0.72))
    for lx in (-0.9, 0.9):
        for ly in (-0.4, 0.4):
            m.lathe("oak", turned_profile(0.04, 0.72, 4, 8), 24, lx, ly)
    bowl = [(0.0, 0.77), (0.06, 0.77)]
    for i in range(1, 41):
        t = i / 40
        bowl.append((0.06 + 0.16 * math.sin(0.5 * math.pi * t), 0.77 + 0.12 * (1 - math.cos(0.5 * math.pi * t))))
    bowl += [(0.21, 0.89), (0.0, 0.89)]
    m.lathe("ceramic", bowl, 64, 0.2, 0.05)
    m.place(0.0, 0.0, 0.0, 0.0)


def chair(m, x, y, angle):
    """A chair facing +x in its own frame: turned legs, seat, back posts, spindles, curved rail."""
    m.place(x, y, 0.0, angle)
    for lx in (-0.2, 0.2):
        for ly in (-0.2, 0.2):
            m.lathe("walnut", turned_profile(0.025, 0.45, 3), 16, lx, ly)
    m.box("walnut", (-0.23, -0.23, 0.45), (0.23, 0.23, 0.49))
    for ly in (-0.2, 0.2):
        m.lathe("walnut", turned_profile(0.02, 0.5, 3), 16, -0.2, ly, 0.49)
    for i in range(1, 6):
        m.lathe("walnut", [(0.008, 0.0), (0.01, 0.2), (0.008, 0.4)], 10, -0.21, -0.2 + 0.4 * i / 6, 0.49)
    rail = 16  # the top rail, a box bent along an arc behind the seat
    for i in range(rail):
        a0, a1 = -0.45 + 0.9 * i / rail, -0.45 + 0.9 * (i + 1) / rail
        p = [(-0.2 - 0.45 * (1 - math.cos(a)) - dx, 0.45 * math.sin(a) * 0.5 / 0.45, z)
             for a in (a0, a1) for dx in (0.0, 0.03) for z in (0.89, 0.99)]
        v = [m.vertex(q) for q in p]
        for a, b, c, d in ((0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
            m.tri("walnut", v[a], v[b], v[c])
            m.tri("walnut", v[a], v[c], v[d])
    m.place(0.0, 0.0, 0.0, 0.0)


def bookcase(m, x0, x1, y_back, depth, rng):
    """Side panels, long shelf boards and rows of books of random size and colour."""
    top = 2.2
    m.box("oak", (x0, y_back - depth, 0.0), (x0 + 0.03, y_back, top))
    m.box("oak", (x1 - 0.03, y_back - depth, 0.0), (x1, y_back, top))
    m.box("oak", (x0, y_back - 0.01, 0.0), (x1, y_back, top))
    shelves = [0.05 + 0.43 * i for i in range(6)]
    for z in shelves:
        m.box("oak", (x0 + 0.03, y_back - depth, z), (x1 - 0.03, y_back - 0.01, z + 0.025))
    colours = ["book_red", "book_blue", "book_green", "book_ochre", "book_cream"]
    for z in shelves[:-1]:
        x = x0 + 0.04
        while True:
            w = rng.uniform(0.02, 0.06)
            if x + w > x1 - 0.04:
                break
            if rng.random() < 0.05:  # a gap
                x += rng.uniform(0.05, 0.2)
                continue
            h = rng.uniform(0.2, 0.36)
            d = rng.uniform(0.15, 0.24)
            m.box(rng.choice(colours), (x, y_back - 0.01 - d, z + 0.025), (x + w - 0.002, y_back - 0.01, z + 0.025 + h))
            x += w


def floor_lamp(m, x, y):
    base = [(0.0, 0.0), (0.18, 0.0), (0.18, 0.02)]
    for i in range(1, 13):
        base.append((0.18 - 0.15 * i / 12, 0.02 + 0.04 * math.sin(0.5 * math.pi * i / 12)))
    base.append((0.0, 0.06))
    m.lathe("iron", base, 48, x, y)
    m.lathe("iron", [(0.012, 0.06), (0.012, 1.45)], 16, x, y)
    shade = []
    for i in range(25):
        t = i / 24
        shade.append((0.12 + 0.14 * t + 0.01 * math.sin(12 * math.pi * t), 1.75 - 0.35 * t))
    m.lathe("shade", shade, 64, x, y)


def write(m, obj_path, mtl_path):
    with open(mtl_path, "w") as f:
        f.write("# Materials of room.obj, written by make_interior.py.\n")
        for name, (r, g, b) in MATERIALS.items():
            f.write(f"newmtl {name}\nKd {r:.3f} {g:.3f} {b:.3f}\n")
    with open(obj_path, "w") as f:
        count = sum(len(t) for t in m.faces.values())
        f.write(f"# A furnished room, written by make_interior.py: {len(m.vertices)} vertices, {count} triangles.\n")
        f.write(f"mtllib {os.path.basename(mtl_path)}\n")
        for x, y, z in m.vertices:
            f.write(f"v {x:.5g} {y:.5g} {z:.5g}\n")
        for name, tris in m.faces.items():
            if not tris:
                continue
            f.write(f"usemtl {name}\n")
            for a, b, c in tris:
                f.write(f"f {a} {b} {c}\n")
    return count


def main():
    rng = random.Random(42)
    m = Mesh()
    shell(m)
    column(m, 2.6, 3.0)
    column(m, 5.4, 3.0)
    m.box("rug", (2.8, 1.6, 0.02), (5.2, 4.4, 0.03))
    table(m, 4.0, 3.0)
    for cx, cy, angle in ((3.3, 2.3, 90), (4.7, 2.3, 90), (3.3, 3.7, -90), (4.7, 3.7, -90), (2.6 + 0.45, 3.0, 0),
                          (5.4 - 0.45, 3.0, 180)):
        chair(m, cx, cy, angle)
    bookcase(m, 0.4, 3.4, 6.0, 0.32, rng)
    bookcase(m, 3.6, 6.2, 6.0, 0.32, rng)
    floor_lamp(m, 7.5, 0.5)
    floor_lamp(m, 0.5, 0.5)
    count = write(m, os.path.join(HERE, "room.obj"), os.path.join(HERE, "room.mtl"))
    print(f"room.obj: {len(m.vertices)} vertices, {count} triangles")


if __name__ == "__main__":
    main()
