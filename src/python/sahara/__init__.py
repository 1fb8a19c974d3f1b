"""sahara: render scenes and cast rays into meshes from Python.

    import sahara
    img = sahara.render({"camera": {...}, "objects": [...]}, spp=16)   # H x W x 3 float32, linear
    sahara.write_image("out.png", img)

See docs/python.md for the whole API.
"""
import os as _os

import numpy as _np

from . import _sahara
from ._sahara import *  # noqa: F401,F403  (RayCaster, Scene, InputError, ...)
from ._sahara import InputError, __version__  # noqa: F401

__all__ = [name for name in dir(_sahara) if not name.startswith("_")] + [
    "Image", "render", "read_image", "write_image", "__version__"]


class Image(_np.ndarray):
    """A rendered image: a float32 H x W x 3 numpy array of linear RGB.

    It remembers the scene's exposure and tone curve (used by write_image for
    8-bit files and by the PNG that Jupyter shows) and `stats`, a dict about
    the render (spp reached, seconds, whether it completed).
    """

    def __new__(cls, array, exposure=0.0, tonemap="clamp", stats=None):
        obj = _np.asarray(array).view(cls)
        obj.exposure = float(exposure)
        obj.tonemap = tonemap
        obj.stats = dict(stats or {})
        return obj

    def __array_finalize__(self, obj):
        # Slices and copies keep how the image should be displayed.
        self.exposure = getattr(obj, "exposure", 0.0)
        self.tonemap = getattr(obj, "tonemap", "clamp")
        self.stats = getattr(obj, "stats", {})

    def _repr_png_(self):
        """The PNG bytes Jupyter shows: the CLI's tone curve and sRGB encoding."""
        if self.ndim != 3 or self.shape[2] != 3 or self.shape[0] < 1 or self.shape[1] < 1:
            return None
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            path = _os.path.join(tmp, "image.png")
            write_image(path, self)
            with open(path, "rb") as f:
                return f.read()


def _scene_object(scene, variant=None):
    if isinstance(scene, Scene):  # noqa: F405
        if variant is not None:
            raise ValueError("variant: a sahara.Scene is already loaded; pass variant to sahara.Scene")
        return scene
    return Scene(scene, variant=variant)  # noqa: F405


def _as_image(result):
    pixels, meta = result
    stats = {k: v for k, v in meta.items() if k not in ("exposure", "tonemap")}
    return Image(pixels, meta["exposure"], meta["tonemap"], stats)


def render(scene=None, *, spp=None, width=None, height=None, seed=None, max_depth=None,
           threads=None, integrator=None, time=None, progress=False, variant=None):
    """Renders a scene and returns an Image (float32 H x W x 3, linear RGB).

    scene: a scene file (.json), a model (.obj, .gltf, .glb, framed as
    `sahara view` frames it), a dict in the scene format, a sahara.Scene, or
    None for the built-in default scene. Each keyword overrides the scene's
    value, as the command line's flag of the same name does; the pixels equal
    those of `sahara render ... -o out.exr` with the same settings.
    time: stop after this many seconds with what is done. threads: 0 or None
    for all cores. progress: draw progress on stderr. variant: the glTF
    model's KHR_materials_variants variant to render, as `sahara view
    --variant` (None: the default materials). The GIL is released
    while rendering; Ctrl-C raises KeyboardInterrupt promptly.
    Raises InputError (a ValueError) for bad scene input, TypeError or
    ValueError for a bad argument.
    """
    return _scene_object(scene, variant).render(
        spp=spp, width=width, height=height, seed=seed, max_depth=max_depth, threads=threads,
        integrator=integrator, time=time, progress=progress)


def _scene_render(self, *, spp=None, width=None, height=None, seed=None, max_depth=None,
                  threads=None, integrator=None, time=None, progress=False):
    """Renders this scene with the given settings (see sahara.render); returns an Image."""
    return _as_image(self._render(
        spp=spp, width=width, height=height, seed=seed, max_depth=max_depth, threads=threads,
        integrator=integrator, time=time, progress=progress))


Scene.render = _scene_render  # noqa: F405


def write_image(path, array, *, exposure=None, tonemap=None):
    """Writes H x W x 3 linear RGB to `path`; the extension picks the format.

    .png is 8-bit sRGB after exposure (stops) and the tone curve (clamp,
    reinhard, aces, filmic), exactly as `sahara render -o out.png` writes;
    .exr, .hdr and .pfm stay linear float. For an Image the defaults are the
    scene's exposure and tone curve, otherwise 0 and clamp. The file is
    written atomically. Raises InputError for an unsupported extension or a
    directory that does not exist.
    """
    if exposure is None:
        exposure = getattr(array, "exposure", 0.0)
    if tonemap is None:
        tonemap = getattr(array, "tonemap", "clamp")
    if not isinstance(tonemap, str):
        raise TypeError(f"tonemap: expected a str, got {type(tonemap).__name__}")
    if isinstance(exposure, bool) or not isinstance(exposure, (int, float, _np.number)):
        raise TypeError(f"exposure: expected a number, got {type(exposure).__name__}")
    if not isinstance(path, (str, bytes, _os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    _sahara._write_image(_os.fsdecode(path), array, exposure=float(exposure), tonemap=tonemap)


def read_image(path):
    """Reads an image file (EXR, HDR, PFM, PNG, JPEG, ...) as an Image of linear
    RGB: float files as stored, 8-bit ones sRGB-decoded; alpha is dropped.
    Raises InputError when the file cannot be read."""
    if not isinstance(path, (str, bytes, _os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    return Image(_sahara._read_image(_os.fsdecode(path)))
