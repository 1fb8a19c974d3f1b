"""Dispersion and diffuse transmission: the same keys in scene dicts as in scene files, the
glTF extensions listed by info and their bad values refused naming the element."""
import numpy as np
import pytest

import sahara
from gltf_docs import write_gltf


def test_dict_materials_take_dispersion_and_diffuse_transmission(workshop):
    workshop["materials"]["leaf"] = {"type": "pbr", "diffuse_transmission": 0.5,
                                     "diffuse_transmission_color": [1, 0.5, 0.2]}
    workshop["materials"]["prism"] = {"type": "pbr", "transmission": 1, "dispersion": 0.5}
    workshop["objects"][0]["material"] = "prism"
    workshop["objects"][1]["material"] = "leaf"
    materials = sahara.Scene(workshop).info()["Materials"]
    by_name = {m["name"]: m for m in materials.values() if isinstance(m, dict)}
    assert by_name["leaf"]["diffuse_transmission"] == 0.5
    assert by_name["prism"]["dispersion"] == 0.5
    workshop["materials"]["leaf"]["diffuse_transmission"] = 2
    with pytest.raises(sahara.InputError, match="diffuse_transmission"):
        sahara.Scene(workshop)


def _triangle_gltf(path, extensions):
    corners = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32)
    return write_gltf(path, [corners], {
        "materials": [{"name": "glass", "extensions": extensions}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    })


def test_gltf_dispersion_and_diffuse_transmission_are_listed_and_checked(tmp_path):
    model = _triangle_gltf(tmp_path / "glass.gltf", {
        "KHR_materials_transmission": {"transmissionFactor": 1},
        "KHR_materials_volume": {"thicknessFactor": 1},
        "KHR_materials_dispersion": {"dispersion": 0.25},
        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.5}})
    materials = sahara.Scene(model).info()["Materials"]
    glass = next(m for m in materials.values() if isinstance(m, dict) and m["name"] == "glass")
    assert glass["dispersion"] == 0.25
    assert glass["diffuse_transmission"] == 0.5
    assert {"KHR_materials_dispersion", "KHR_materials_diffuse_transmission"} <= set(glass["extensions"])
    bad = _triangle_gltf(tmp_path / "bad.gltf", {"KHR_materials_dispersion": {"dispersion": -1}})
    with pytest.raises(sahara.InputError,
                       match=r"materials\[0\]\.extensions\.KHR_materials_dispersion\.dispersion: "
                             r"must be a number >= 0"):
        sahara.Scene(bad)
