"""sahara.render and sahara.Scene: the same pixels as the command line, settings, Scene reuse."""
import json
import subprocess

import numpy as np
import pytest

import sahara
from gltf_docs import write_gltf


def read_exr(path):
    """The command line's EXR read back (float channels, as stored)."""
    img = sahara.read_image(path)
    assert img.dtype == np.float32
    return img


def test_render_returns_linear_float32_image(workshop):
    img = sahara.render(workshop)
    assert isinstance(img, np.ndarray) and isinstance(img, sahara.Image)
    assert img.dtype == np.float32 and img.shape == (24, 32, 3)
    assert np.isfinite(img).all() and img.max() > 0
    assert img.stats["spp"] == 4 and img.stats["complete"]


def test_an_unlit_material_in_a_dict_shows_exactly_its_colour(workshop):
    """The dict goes through the scene-file parser: `unlit` works there as in a file."""
    workshop["materials"]["sign"] = {"type": "unlit", "color": [0.25, 0.5, 0.75]}
    workshop["objects"][0]["material"] = "sign"
    img = sahara.render(workshop, width=8, height=8, spp=2)
    assert np.allclose(img[4, 4], [0.25, 0.5, 0.75], rtol=1e-6, atol=0)
    assert sahara.Scene(workshop).info()["Materials"]["unlit"] == 1


def test_keywords_override_the_scene(workshop):
    img = sahara.render(workshop, width=10, height=7, spp=1, max_depth=2)
    assert img.shape == (7, 10, 3)
    assert img.stats["spp"] == 1


def test_same_seed_same_pixels_other_seed_other_pixels(workshop):
    a = sahara.render(workshop, seed=3, threads=1)
    b = sahara.render(workshop, seed=3, threads=2)
    c = sahara.render(workshop, seed=4)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("integrator", ["path", "normals", "albedo"])
def test_pixels_equal_the_command_line_exr(workshop, sahara_exe, tmp_path, integrator):
    scene_file = tmp_path / "workshop.json"
    scene_file.write_text(json.dumps(workshop))
    exr = tmp_path / "cli.exr"
    settings = dict(spp=3, width=20, height=14, seed=7, max_depth=5)
    subprocess.run([sahara_exe, "render", str(scene_file), "-o", str(exr), "--quiet",
                    "--spp", "3", "--width", "20", "--height", "14", "--seed", "7",
                    "--max-depth", "5", "--integrator", integrator], check=True)
    cli = read_exr(exr)
    from_file = sahara.render(str(scene_file), integrator=integrator, **settings)
    from_dict = sahara.render(workshop, integrator=integrator, **settings)
    assert cli.shape == from_dict.shape == (14, 20, 3)
    assert np.array_equal(from_file, cli)
    assert np.array_equal(from_dict, cli)


def test_default_scene_equals_the_command_line(sahara_exe, tmp_path):
    exr = tmp_path / "default.exr"
    subprocess.run([sahara_exe, "render", "-o", str(exr), "--quiet", "--spp", "2", "--size", "16x12"],
                   check=True)
    assert np.array_equal(sahara.render(None, spp=2, width=16, height=12), read_exr(exr))


def test_scene_loads_once_and_renders_with_other_settings(workshop):
    scene = sahara.Scene(workshop)
    small = scene.render(width=8, height=6, spp=1)
    large = scene.render(width=16, height=12, spp=2)
    assert small.shape == (6, 8, 3) and large.shape == (12, 16, 3)
    # Settings of one render do not stick to the next.
    assert scene.render().shape == (24, 32, 3)
    assert np.array_equal(scene.render(seed=1), sahara.render(workshop, seed=1))


def test_scene_info_is_the_info_report(workshop):
    info = sahara.Scene(workshop).info()
    assert info["Objects"]["Spheres"] == 2
    assert info["Materials"]["Total"] == 3  # the default material and the two named ones
    assert "Load" in info["Time"] and "Build" in info["Time"]


def test_scene_info_names_obj_vertex_colours(tmp_path):
    obj = tmp_path / "coloured.obj"
    obj.write_text("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n")
    scene = {"format": "scene/1", "camera": {"position": [0, -3, 1], "look_at": [0, 0, 0]},
             "objects": [{"type": "mesh", "file": str(obj)}]}
    materials = sahara.Scene(scene).info()["Materials"]
    coloured = [m["type"] for m in materials.values() if isinstance(m, dict) and m["vertex_colors"]]
    assert coloured == ["lambertian"]


def test_bvh_stats_has_the_keys_of_sahara_bvh_json(workshop, sahara_exe, tmp_path):
    scene_file = tmp_path / "workshop.json"
    scene_file.write_text(json.dumps(workshop))
    out = subprocess.run([sahara_exe, "bvh", str(scene_file), "--json", "--size", "8"],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    stats = sahara.Scene(workshop).bvh_stats(width=8, height=8)
    assert list(stats) == list(cli)
    assert stats["primitives"] == cli["primitives"] == 2
    assert stats["nodes"] == cli["nodes"]
    assert stats["rays"]["primary"]["count"] == 64


def test_bvh_cost_integrator(workshop):
    img = sahara.render(workshop, integrator="bvh-cost", width=40, height=30)
    assert img.dtype == np.float32 and img.shape[2] == 3 and img.shape[1] == 40
    assert img.stats["mean_cost"] > 0


def test_relative_paths_in_a_dict_resolve_against_the_cwd(repo, monkeypatch):
    monkeypatch.chdir(repo / "tests" / "data")
    obj = next(p for p in (repo / "tests" / "data" / "obj").rglob("*.obj"))
    scene = {
        "camera": {"position": [0, -5, 1], "look_at": [0, 0, 0]},
        "objects": [{"type": "mesh", "file": str(obj.relative_to(repo / "tests" / "data"))}],
    }
    assert sahara.Scene(scene).info()["Objects"]["Triangles"] > 0


def test_a_model_path_is_framed_like_sahara_view(repo):
    glb = next((repo / "tests" / "data" / "gltf").rglob("*.gltf"))
    img = sahara.render(str(glb), width=16, height=12, spp=1)
    assert img.shape == (12, 16, 3) and img.max() > 0


def test_the_readme_dict_is_the_default_scene(repo):
    # The README's five lines: run them (smaller) and compare with the built-in scene.
    readme = (repo / "README.md").read_text()
    code = readme.split("```python\n", 1)[1].split("```", 1)[0]
    code = code.replace("spp=64)", "spp=2, width=24, height=18)").replace('sahara.write_image("workshop.png", img)', "")
    names = {}
    exec(code, names)
    assert np.array_equal(names["img"], sahara.render(None, spp=2, width=24, height=18))


def test_a_time_limit_returns_what_is_done(workshop):
    img = sahara.render(workshop, width=64, height=48, spp=1 << 20, time=0.2)
    assert img.shape == (48, 64, 3) and np.isfinite(img).all()
    assert not img.stats["complete"]
    assert img.stats["spp"] < (1 << 20)


def _variants_gltf(path):
    """A quad in unlit grey; its variant "Red" maps it to unlit red (KHR_materials_variants)."""
    corners = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], np.uint16)

    def unlit(name, rgb):
        return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": rgb + [1]},
                "extensions": {"KHR_materials_unlit": {}}}

    return write_gltf(path, [corners, indices], {
        "extensionsUsed": ["KHR_materials_variants", "KHR_materials_unlit"],
        "extensions": {"KHR_materials_variants": {"variants": [{"name": "Red"}]}},
        "materials": [unlit("grey", [0.5, 0.5, 0.5]), unlit("red", [1, 0, 0])],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0}, "indices": 1, "material": 0,
            "extensions": {"KHR_materials_variants": {"mappings": [{"material": 1, "variants": [0]}]}}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    })


def test_a_glTF_variant_renders_its_colours(tmp_path):
    model = _variants_gltf(tmp_path / "variants.gltf")
    assert np.allclose(sahara.render(model, width=8, height=8, spp=2)[4, 4], [0.5, 0.5, 0.5])
    assert np.allclose(sahara.render(model, width=8, height=8, spp=2, variant="Red")[4, 4], [1, 0, 0])
    scene = sahara.Scene(model, variant="Red")
    assert np.allclose(scene.render(width=8, height=8, spp=2)[4, 4], [1, 0, 0])
    with pytest.raises(sahara.InputError, match="no material variant named 'Green'; the file has: Red"):
        sahara.render(model, variant="Green")
    with pytest.raises(ValueError, match="variant"):
        sahara.render(scene, variant="Red")
    with pytest.raises(ValueError, match="variant"):
        sahara.Scene({"objects": []}, variant="Red")
    with pytest.raises(TypeError, match="variant"):
        sahara.Scene(model, variant=1)
