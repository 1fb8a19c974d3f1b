#!/usr/bin/python3
# Usage: measure.py SAHARA_BINARY OUTDIR
# The stress scene of tests/render/test_stress.cpp (sahara's default scene:
# camera at the origin looking +y, a red sphere on a big green ground sphere)
# written as a scene file at offsets 0, 1e5, 1e6, 1e7 on all three axes;
# prints the fraction of pixels that differ from the scene at the origin.
import json, subprocess, sys, struct
import numpy as np
exe, out = sys.argv[1], sys.argv[2]

def scene(o):
    p = lambda x, y, z: [o + x, o + y, o + z]
    return {"render": {"width": 320, "height": 240, "spp": 16, "seed": 3},
            "camera": {"position": p(0, 0, 0), "look_at": p(0, 1, 0), "up": [0, 0, 1], "vfov": 90},
            "materials": {"red": {"type": "lambertian", "albedo": [0.8, 0.1, 0.1]},
                          "green": {"type": "lambertian", "albedo": [0.2, 0.7, 0.2]}},
            "objects": [{"type": "sphere", "center": p(0, 10, 0), "radius": 5, "material": "red"},
                        {"type": "sphere", "center": p(0, 10, -100), "radius": 95, "material": "green"}]}

def read_pfm(f):
    with open(f, "rb") as fh:
        assert fh.readline().strip() == b"PF"
        w, h = map(int, fh.readline().split())
        scale = float(fh.readline())
        a = np.frombuffer(fh.read(), dtype="<f4" if scale < 0 else ">f4")
    return a.reshape(h, w, 3)

imgs = {}
for o in [0.0, 1e5, 1e6, 1e7]:
    sf, img = f"{out}/stress_{o:g}.json", f"{out}/stress_{o:g}.pfm"
    json.dump(scene(o), open(sf, "w"))
    subprocess.run([exe, "render", sf, "-o", img, "-q", "--threads", "2"], check=True)
    imgs[o] = read_pfm(img)
for o in [1e5, 1e6, 1e7]:
    d = np.abs(imgs[o] - imgs[0.0]).max(axis=2)
    print(f"offset {o:g}: pixels differing {np.mean(d > 0) * 100:.2f}%, by > 0.01: {np.mean(d > 0.01) * 100:.2f}%")
