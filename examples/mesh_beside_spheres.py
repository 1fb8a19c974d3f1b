"""A downloaded mesh (OBJ or glTF, path on the command line) standing on a floor
beside a glass and a metal sphere, rendered with sahara from a Python dict.

    PYTHONPATH=build/python python3 examples/mesh_beside_spheres.py MODEL [-o OUT.png] [--spp N]

The mesh is scaled to a height of 2 and set on the floor: its bounds come from
Scene.info() of a scene holding only the mesh, so any model lands in the picture.
"""
import argparse
import os

import sahara


def placement(model):
    """Scale, rotation and translation that stand the model, 2 units tall, on z = 0 at the origin."""
    # The file's own coordinates: a scene holding only the mesh, no transform.
    probe = {"camera": {"position": [0, -1, 0], "look_at": [0, 0, 0]},
             "objects": [{"type": "mesh", "file": os.path.abspath(model)}]}
    bounds = sahara.Scene(probe).info()["Bounds"]
    lo, hi = bounds["Min"], bounds["Max"]
    size = [b - a for a, b in zip(lo, hi)]
    # glTF is y-up by definition; an OBJ is taken as z-up only when clearly taller along z.
    z_up = os.path.splitext(model)[1].lower() == ".obj" and size[2] > 1.5 * size[1]
    up = 2 if z_up else 1
    scale = 2.0 / (size[up] or 1.0)
    center = [(a + b) / 2 for a, b in zip(lo, hi)]
    if z_up:
        return {"scale": scale, "translate": [-center[0] * scale, -center[1] * scale, -lo[2] * scale]}
    # Rotating 90 degrees about x turns +y into +z and +z into -y.
    return {"scale": scale, "rotate": [90, 0, 0],
            "translate": [-center[0] * scale, center[2] * scale, -lo[1] * scale]}


def scene_with(model):
    return {
        "render": {"width": 800, "height": 450, "spp": 64, "max_depth": 8, "tonemap": "aces", "exposure": -0.5},
        "camera": {"position": [0, -7, 2.2], "look_at": [0, 0, 0.9], "up": [0, 0, 1], "vfov": 40},
        "background": {"type": "gradient", "bottom": [1, 1, 1], "top": [0.45, 0.6, 0.9], "up": [0, 0, 1]},
        "materials": {
            "floor": {"type": "lambertian", "albedo": [0.4, 0.4, 0.4]},
            "glass": {"type": "dielectric", "ior": 1.5},
            "steel": {"type": "metal", "albedo": [0.85, 0.85, 0.9], "roughness": 0.1},
        },
        "objects": [
            {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "floor"},
            {"type": "mesh", "file": os.path.abspath(model), "transform": placement(model)},
            {"type": "sphere", "center": [-2.2, 0.5, 0.8], "radius": 0.8, "material": "glass"},
            {"type": "sphere", "center": [2.2, 0.5, 0.8], "radius": 0.8, "material": "steel"},
        ],
        "lights": [{"type": "directional", "direction": [-1, 2, -3], "irradiance": [2.0, 1.9, 1.7]}],
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", help="an .obj, .gltf or .glb file")
    parser.add_argument("-o", "--output", default="mesh_beside_spheres.png")
    parser.add_argument("--spp", type=int, default=64)
    args = parser.parse_args()

    scene = sahara.Scene(scene_with(args.model))
    print("triangles:", scene.info()["Objects"]["Triangles"])
    img = scene.render(spp=args.spp, progress=True)
    sahara.write_image(args.output, img)
    print("wrote", args.output)


if __name__ == "__main__":
    main()
