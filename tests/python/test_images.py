"""write_image writes what the command line writes; images show themselves in Jupyter."""
import json
import subprocess

import numpy as np
import pytest

import sahara


@pytest.mark.parametrize("tonemap, exposure", [("clamp", 0), ("aces", 1.5)])
def test_png_equals_the_command_line_png(workshop, sahara_exe, tmp_path, tonemap, exposure):
    workshop["render"].update(tonemap=tonemap, exposure=exposure)
    scene_file = tmp_path / "workshop.json"
    scene_file.write_text(json.dumps(workshop))
    subprocess.run([sahara_exe, "render", str(scene_file), "-o", str(tmp_path / "cli.png"), "--quiet"],
                   check=True)
    img = sahara.render(workshop)
    assert img.tonemap == tonemap and img.exposure == exposure
    sahara.write_image(tmp_path / "py.png", img)
    # The pixels, not the bytes: the files' metadata differ (render time, integrator).
    assert np.array_equal(sahara.read_image(tmp_path / "py.png"), sahara.read_image(tmp_path / "cli.png"))


def test_exr_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(1)
    pixels = rng.random((5, 7, 3), dtype=np.float32) * 100
    sahara.write_image(tmp_path / "a.exr", pixels)
    assert np.array_equal(sahara.read_image(tmp_path / "a.exr"), pixels)


def test_png_applies_exposure_and_clips(tmp_path):
    pixels = np.full((2, 3, 3), 0.25, np.float32)
    sahara.write_image(tmp_path / "bright.png", pixels, exposure=2)  # 0.25 * 2**2 = 1: white
    back = sahara.read_image(tmp_path / "bright.png")
    assert back.shape == (2, 3, 3)
    assert np.allclose(back, 1.0)


def test_float64_and_non_contiguous_arrays(tmp_path):
    pixels = np.linspace(0, 1, 4 * 6 * 3).reshape(4, 6, 3)  # float64
    sahara.write_image(tmp_path / "f64.exr", pixels[:, ::2, :])
    assert np.allclose(sahara.read_image(tmp_path / "f64.exr"), pixels[:, ::2, :], atol=1e-7)


def test_repr_png_is_a_png_of_the_image(workshop):
    img = sahara.render(workshop, spp=1)
    png = img._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    # Slices stay images; things that are not H x W x 3 have no picture.
    assert isinstance(img[2:5], sahara.Image)
    assert img[..., 0]._repr_png_() is None
