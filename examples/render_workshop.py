"""The workshop scene (a red sphere on a green ground sphere under a gradient sky),
built as a Python dict and rendered with sahara.

    PYTHONPATH=build/python python3 examples/render_workshop.py [OUT.png] [--spp N]
"""
import argparse

import sahara


def workshop_scene(width=640, height=480):
    """The scene of scenes/workshop.json, written in Python."""
    return {
        "render": {"width": width, "height": height, "spp": 64, "max_depth": 8},
        "camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "up": [0, 0, 1], "vfov": 90},
        "background": {"type": "gradient", "bottom": [1, 1, 1], "top": [0.5, 0.7, 1.0], "up": [0, 0, 1]},
        "materials": {
            "red": {"type": "lambertian", "albedo": [0.8, 0.1, 0.1]},
            "green": {"type": "lambertian", "albedo": [0.2, 0.7, 0.2]},
        },
        "objects": [
            {"type": "sphere", "center": [0, 10, 0], "radius": 5, "material": "red"},
            {"type": "sphere", "center": [0, 10, -100], "radius": 95, "material": "green"},
        ],
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", nargs="?", default="workshop.png")
    parser.add_argument("--spp", type=int, default=64)
    args = parser.parse_args()

    img = sahara.render(workshop_scene(), spp=args.spp, progress=True)
    print(f"{img.shape[1]}x{img.shape[0]}, {img.stats['spp']} spp in {img.stats['seconds']:.2f} s, "
          f"mean radiance {img.mean():.3f}")
    sahara.write_image(args.output, img)
    print("wrote", args.output)


if __name__ == "__main__":
    main()
