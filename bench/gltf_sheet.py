#!/usr/bin/env python3
"""Side-by-side sheet: each glTF model's reference picture next to `sahara view`.

    python3 bench/gltf_sheet.py ASSETS_GLTF_DIR -o OUT_DIR [--sahara build/sahara]
                                [--size 256] [--spp 32] [--only SUBSTRING]

ASSETS_GLTF_DIR holds Khronos sample models (NAME/glTF/NAME.gltf with
NAME/screenshot/screenshot.*), other models (DIR/*.gltf, no reference) and
glTF asset-generator folders (asset-generator/GROUP/GROUP_NN.gltf with
GROUP/Figures/SampleImages/GROUP_NN.png). Every model is rendered with
`sahara view` into OUT_DIR/renders/; OUT_DIR/sheet_GROUP.png then shows, per
model, the reference on the left, sahara on the right and the name under both.
The references' camera and lighting are the authors' own, so compare shape,
colour, metalness and orientation, not pixels. Needs OpenImageIO's Python
bindings (Debian: python3-openimageio).
"""
import argparse
import os
import subprocess
import sys

try:
    import OpenImageIO as oiio
    from OpenImageIO import ImageBufAlgo as iba
except ImportError:  # pragma: no cover
    raise SystemExit("needs OpenImageIO's Python bindings (Debian: apt-get install python3-openimageio)")

LABEL_HEIGHT = 22
PAIRS_PER_ROW = 3
FONT = "DejaVuSans"


def find_models(root):
    """(group, name, model path, reference path or None), in a stable order."""
    models = []
    for entry in sorted(os.listdir(root)):
        folder = os.path.join(root, entry)
        if not os.path.isdir(folder):
            continue
        if entry == "asset-generator":
            for group in sorted(os.listdir(folder)):
                gdir = os.path.join(folder, group)
                if not os.path.isdir(gdir):
                    continue
                for f in sorted(os.listdir(gdir)):
                    if f.endswith(".gltf"):
                        stem = f[:-5]
                        ref = os.path.join(gdir, "Figures", "SampleImages", stem + ".png")
                        models.append((group, stem, os.path.join(gdir, f), ref if os.path.exists(ref) else None))
            continue
        khronos = os.path.join(folder, "glTF", entry + ".gltf")
        if os.path.exists(khronos):
            shots = os.path.join(folder, "screenshot")
            ref = None
            if os.path.isdir(shots):
                names = sorted(n for n in os.listdir(shots) if n.startswith("screenshot."))
                ref = os.path.join(shots, names[0]) if names else None
            models.append(("samples", entry, khronos, ref))
            continue
        for f in sorted(os.listdir(folder)):
            if f.endswith((".gltf", ".glb")):
                models.append(("samples", entry, os.path.join(folder, f), None))
                break
    return models


def render(sahara, model, out, size, spp):
    cmd = [sahara, "view", model, "--size", f"{size}x{size}", "--spp", str(spp), "--seed", "1", "--quiet", "-o", out]
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        print(f"{os.path.basename(model)}: sahara exit {done.returncode}: {done.stderr.strip()}", file=sys.stderr)
        return False
    return True


def fitted(path, size):
    """The image at path scaled to fit size x size (aspect kept), centred on grey; RGB."""
    tile = oiio.ImageBuf(oiio.ImageSpec(size, size, 3, oiio.FLOAT))
    iba.fill(tile, (0.2, 0.2, 0.2))
    if path is None:
        iba.render_text(tile, 10, size // 2, "no reference", 16, FONT, (1, 1, 1))
        return tile
    src = oiio.ImageBuf(path)
    spec = src.spec()
    if src.has_error or spec.width == 0:
        iba.render_text(tile, 10, size // 2, "unreadable", 16, FONT, (1, 0.3, 0.3))
        return tile
    rgb = iba.channels(src, (0, 1, 2)) if spec.nchannels >= 3 else iba.channels(src, (0, 0, 0))
    scale = size / max(spec.width, spec.height)
    w, h = max(1, round(spec.width * scale)), max(1, round(spec.height * scale))
    small = iba.resize(rgb, roi=oiio.ROI(0, w, 0, h, 0, 1, 0, 3))
    iba.paste(tile, (size - w) // 2, (size - h) // 2, 0, 0, small)
    return tile


def write_sheet(path, entries, size, renders):
    rows = (len(entries) + PAIRS_PER_ROW - 1) // PAIRS_PER_ROW
    cell_w, cell_h = 2 * size + 8, size + LABEL_HEIGHT + 8
    sheet = oiio.ImageBuf(oiio.ImageSpec(cell_w * PAIRS_PER_ROW, cell_h * rows, 3, oiio.UINT8))
    iba.fill(sheet, (1, 1, 1))
    for i, (_, name, _, ref) in enumerate(entries):
        x, y = (i % PAIRS_PER_ROW) * cell_w, (i // PAIRS_PER_ROW) * cell_h
        iba.paste(sheet, x, y, 0, 0, fitted(ref, size))
        iba.paste(sheet, x + size, y, 0, 0, fitted(renders.get(name), size))
        iba.render_text(sheet, x + 4, y + size + LABEL_HEIGHT - 6, f"{name}: reference | sahara", 15, FONT, (0, 0, 0))
    if not sheet.write(path):
        raise SystemExit(f"{path}: {sheet.geterror()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("assets", help="folder of glTF models (e.g. the shared assets' gltf/)")
    ap.add_argument("-o", "--out", required=True, help="output folder for renders and sheets")
    ap.add_argument("--sahara", default="build/sahara", help="the sahara executable")
    ap.add_argument("--size", type=int, default=256, help="tile size in pixels")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--only", default="", help="render only models whose name contains this")
    args = ap.parse_args()

    models = find_models(args.assets)
    os.makedirs(os.path.join(args.out, "renders"), exist_ok=True)
    renders = {}
    for group, name, model, ref in models:
        out = os.path.join(args.out, "renders", name + ".png")
        if args.only in name and not render(args.sahara, model, out, args.size, args.spp):
            continue
        if os.path.exists(out):
            renders[name] = out
    for group in dict.fromkeys(g for g, _, _, _ in models):
        entries = [m for m in models if m[0] == group]
        path = os.path.join(args.out, f"sheet_{group}.png")
        write_sheet(path, entries, args.size, renders)
        print(path)


if __name__ == "__main__":
    main()
