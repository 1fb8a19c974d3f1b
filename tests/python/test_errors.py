"""Bad input raises Python exceptions with the command line's messages; nothing crashes."""
import numpy as np
import pytest

import sahara


def test_input_error_is_a_value_error():
    assert issubclass(sahara.InputError, ValueError)


def test_a_bad_dict_names_the_key_path(workshop):
    workshop["objects"].append({"type": "sphere", "center": [0, 0, 0], "radius": "big"})
    with pytest.raises(sahara.InputError, match=r"objects\[2\]\.radius: expected a number"):
        sahara.render(workshop)


def test_a_dict_gets_the_same_message_as_a_file(workshop, tmp_path):
    import json
    workshop["objects"][1]["radius"] = -1
    scene_file = tmp_path / "bad.json"
    scene_file.write_text(json.dumps(workshop))
    with pytest.raises(sahara.InputError) as from_dict:
        sahara.Scene(workshop)
    with pytest.raises(sahara.InputError) as from_file:
        sahara.Scene(scene_file)
    after_name = lambda e: str(e.value).split(": ", 1)[1]  # noqa: E731  (the file name differs)
    assert after_name(from_dict) == after_name(from_file)
    assert "objects[1].radius" in str(from_dict.value)


@pytest.mark.parametrize("change, pattern", [
    (lambda d: d.pop("camera"), "camera"),
    (lambda d: d.update(colour=1), "colour"),
    (lambda d: d["materials"]["red"].update(type="plastic"), r"materials\.red\.type"),
    (lambda d: d["materials"]["red"].update(type="unlit"), r"materials\.red\.albedo: unknown key .*color"),
    (lambda d: d["objects"][0].update(center=[0, 1]), r"objects\[0\]\.center"),
    (lambda d: d["objects"][0].update(center=[0, float("nan"), 0]), r"objects\[0\]\.center"),
    (lambda d: d["objects"][0].update(material="missing"), r"objects\[0\]\.material"),
    (lambda d: d["objects"].append({"type": "mesh", "file": "no/such/file.obj"}), "no/such/file.obj"),
])
def test_bad_scene_dicts(workshop, change, pattern):
    change(workshop)
    with pytest.raises(sahara.InputError, match=pattern):
        sahara.Scene(workshop)


@pytest.mark.parametrize("value, shown", [(float("nan"), "nan"), (float("-inf"), "-inf"), (np.float32("inf"), "inf")])
def test_a_non_finite_number_in_a_dict_is_named_as_such(workshop, value, shown):
    workshop["objects"][0]["radius"] = value
    with pytest.raises(sahara.InputError, match=r"objects\[0\]\.radius: expected a finite number, got " + shown):
        sahara.Scene(workshop)


@pytest.mark.parametrize("seed", [2 ** 64 - 1, np.uint64(2 ** 64 - 1)])
def test_a_dict_seed_may_use_all_64_bits_as_in_a_file(workshop, seed):
    workshop["render"] = {"seed": seed}
    assert sahara.Scene(workshop).settings["seed"] == 2 ** 64 - 1


def test_values_without_a_json_form_are_type_errors(workshop):
    workshop["objects"][0]["center"] = {1, 2, 3}
    with pytest.raises(TypeError, match=r"scene: objects\[0\]\.center: set"):
        sahara.Scene(workshop)
    with pytest.raises(TypeError, match="keys must be strings"):
        sahara.Scene({1: 2})


def test_a_dict_containing_itself_is_an_error_not_a_crash(workshop):
    loop = []
    loop.append(loop)
    workshop["objects"][0]["center"] = loop
    with pytest.raises(ValueError, match="nested too deeply"):
        sahara.Scene(workshop)


def test_numpy_values_are_accepted(workshop):
    workshop["objects"][0]["center"] = np.array([0.0, 10.0, 0.0])
    workshop["objects"][0]["radius"] = np.float32(5)
    assert sahara.render(workshop, spp=1).shape == (24, 32, 3)


def test_missing_and_unknown_files():
    with pytest.raises(sahara.InputError, match="no_such_scene.json"):
        sahara.Scene("no_such_scene.json")
    with pytest.raises(TypeError, match="scene: expected a path, a dict or None, got list"):
        sahara.Scene([1, 2])


@pytest.mark.parametrize("kwargs, error, pattern", [
    (dict(spp="4"), TypeError, "spp: expected an integer, got str"),
    (dict(spp=0), ValueError, "spp: expected an integer in"),
    (dict(spp=2.5), TypeError, "spp"),
    (dict(width=True), TypeError, "width"),
    (dict(height=-3), ValueError, "height"),
    (dict(max_depth=5000), ValueError, "max_depth"),
    (dict(seed=-1), ValueError, "seed"),
    (dict(seed=2**70), ValueError, "seed"),
    (dict(threads="all"), TypeError, "threads"),
    (dict(integrator="magic"), ValueError, "integrator: expected path"),
    (dict(integrator=3), TypeError, "integrator"),
    (dict(time=-1.0), ValueError, "time"),
    (dict(time="soon"), TypeError, "time"),
])
def test_bad_render_arguments_name_the_argument(workshop, kwargs, error, pattern):
    with pytest.raises(error, match=pattern):
        sahara.render(workshop, **kwargs)


def test_unknown_keyword_is_a_type_error(workshop):
    with pytest.raises(TypeError):
        sahara.render(workshop, samples=4)


@pytest.mark.parametrize("array, error, pattern", [
    (np.zeros((4, 4)), ValueError, "array: expected an H x W x 3 array"),
    (np.zeros((4, 4, 4), np.float32), ValueError, "array"),
    (np.zeros((0, 4, 3), np.float32), ValueError, "array"),
    (np.array([["a"] * 3] * 2).reshape(1, 2, 3), TypeError, "array: expected a float or integer array"),
    ("pixels", TypeError, "array"),
])
def test_bad_arrays_for_write_image(tmp_path, array, error, pattern):
    with pytest.raises(error, match=pattern):
        sahara.write_image(tmp_path / "x.png", array)


def test_bad_image_paths(tmp_path):
    img = np.zeros((2, 2, 3), np.float32)
    with pytest.raises(sahara.InputError):
        sahara.write_image(tmp_path / "x.unknown", img)
    with pytest.raises(sahara.InputError):
        sahara.write_image(tmp_path / "no" / "such" / "dir.png", img)
    with pytest.raises(sahara.InputError):
        sahara.read_image(tmp_path / "missing.exr")
    with pytest.raises(ValueError, match="tonemap"):
        sahara.write_image(tmp_path / "x.png", img, tonemap="sepia")


@pytest.mark.parametrize("name, pattern", [
    ("x.bmp", "unsupported output format"),   # OpenImageIO could write it; the CLI refuses it too
    ("x", "unsupported output format"),
    ("sub.png", "is a directory"),
    ("", "unsupported output format"),
])
def test_image_paths_the_command_line_refuses(tmp_path, name, pattern):
    (tmp_path / "sub.png").mkdir()
    with pytest.raises(sahara.InputError, match=pattern):
        sahara.write_image(tmp_path / name if name else "", np.zeros((2, 2, 3), np.float32))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub.png"]


def test_an_image_larger_than_the_command_line_allows_is_refused_before_any_work(tmp_path):
    huge = np.broadcast_to(np.float32(0), (40000, 2, 3))  # no memory behind it
    with pytest.raises(ValueError, match="1..32768"):
        sahara.write_image(tmp_path / "x.png", huge)


def test_a_missing_file_in_a_dict_names_the_directory_it_was_looked_for_in(workshop, tmp_path, monkeypatch):
    """A dict has no scene file: the message names the current directory, where relative paths resolve."""
    monkeypatch.chdir(tmp_path)
    workshop["objects"].append({"type": "mesh", "file": "meshes/none.obj"})
    with pytest.raises(sahara.InputError) as e:
        sahara.Scene(workshop)
    assert str(e.value).endswith(f"objects[2].file: file not found: meshes/none.obj "
                                 f"(relative paths resolve against {tmp_path.resolve()})")
    workshop["objects"][2]["file"] = str(tmp_path / "none.obj")
    with pytest.raises(sahara.InputError) as e:
        sahara.Scene(workshop)
    assert str(e.value).endswith(f"file not found: {tmp_path / 'none.obj'}")
