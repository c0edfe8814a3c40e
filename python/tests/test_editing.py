"""Scenes edited in place: `scene.camera.eye = ...`, `scene.materials["white"].color = ...`.
An edited scene is the scene of the edited file; a bad edit is the CLI's error, naming the
field, and leaves the scene as it was."""

import numpy as np
import pytest

import glint

SETTINGS = dict(width=12, height=10, spp=2, device="cpu")


def edited_file(tmp_path, cornell, old, new):
    """The Cornell box file with one line changed, under the same name in another folder."""
    text = cornell.read_text()
    assert old in text
    path = tmp_path / cornell.name
    path.write_text(text.replace(old, new, 1))
    return path


def test_camera_edit_equals_the_edited_file(cornell, tmp_path):
    scene = glint.load(cornell)
    before = glint.render(scene, **SETTINGS)
    scene.camera.eye = (278, 278, -600)
    assert scene.camera.eye == [278, 278, -600]
    edited = glint.load_string(
        edited_file(tmp_path, cornell, "eye = [278.0, 278.0, -800.0]", "eye = [278, 278, -600]").read_text(),
        path=str(cornell),
    )
    assert scene == edited
    after = glint.render(scene, **SETTINGS)
    assert not np.array_equal(before, after)
    assert np.array_equal(after, glint.render(edited, **SETTINGS))


def test_an_orthographic_camera_equals_the_edited_file(cornell, tmp_path):
    """projection = "orthographic" with the view's height, set as a whole camera table (each
    field alone would not validate: vfov and height exclude each other)."""
    scene = glint.load(cornell)
    perspective = glint.render(scene, **SETTINGS)
    camera = scene.camera.to_dict()
    del camera["vfov"]
    camera.update(projection="orthographic", height=600.0)
    scene.camera = camera
    assert scene.camera.projection == "orthographic" and scene.camera.height == 600.0
    path = edited_file(
        tmp_path, cornell, "vfov = 40.0", 'projection = "orthographic"\nheight = 600.0'
    )
    edited = glint.load_string(path.read_text(), path=str(cornell))
    assert scene == edited
    image = glint.render(scene, **SETTINGS)
    assert not np.array_equal(image, perspective)
    assert np.array_equal(image, glint.render(edited, **SETTINGS))
    for field, value, message in [
        ("vfov", 40.0, "no field of view"),
        ("aperture", 10.0, "no lens"),
        ("height", -1.0, "> 0"),
        ("projection", "fisheye", "unknown projection"),
    ]:
        with pytest.raises(glint.SceneError, match=message) as error:
            scene.camera[field] = value
        assert error.value.field == f"camera.{field}"
    assert scene == edited


def test_material_edit_equals_the_edited_file(cornell, tmp_path):
    scene = glint.load(cornell)
    scene.materials["white"].color = (0.5, 0.5, 0.5)
    assert scene.materials["white"].color == [0.5, 0.5, 0.5]
    assert scene.materials.white.type == "diffuse"
    path = edited_file(tmp_path, cornell, "color = [0.73, 0.73, 0.73]", "color = [0.5, 0.5, 0.5]")
    assert scene == glint.load_string(path.read_text(), path=str(cornell))
    assert scene != glint.load(cornell)


def test_edits_of_arrays_render_settings_and_whole_tables(cornell):
    scene = glint.load(cornell)
    radius = scene.spheres[0].radius
    scene.spheres[0].radius = radius / 2
    assert scene.spheres[0].radius == radius / 2
    scene.render.spp = 3
    assert scene.spp == 3 and scene.render.spp == 3
    scene.materials["gold"] = {"type": "metal", "color": [1.0, 0.8, 0.4], "roughness": 0.3}
    scene.spheres[1].material = "gold"
    n = len(scene.spheres)
    scene.spheres.append({"center": [100.0, 50.0, 100.0], "radius": 50.0, "material": "gold"})
    assert len(scene.spheres) == n + 1
    del scene.spheres[n]
    assert len(scene.spheres) == n
    # The structure round-trips through load_dict.
    assert glint.load_dict(scene.to_dict(), path=str(cornell)) == scene


def test_reading_gives_copies(cornell):
    scene = glint.load(cornell)
    eye = scene.camera.eye
    eye[0] = 0.0
    assert scene.camera.eye[0] == 278.0
    as_dict = scene.to_dict()
    as_dict["camera"]["vfov"] = 10.0
    assert scene.camera.vfov == 40.0


def test_a_bad_edit_raises_scene_error_naming_the_field_and_changes_nothing(cli, cornell, tmp_path):
    scene = glint.load(cornell)
    with pytest.raises(glint.SceneError) as error:
        scene.spheres[0].radius = -90.0
    # The CLI's message for the same value in the file, less the line and column (which would
    # be those of TOML text the user never saw).
    path = edited_file(tmp_path, cornell, "radius = 90.0", "radius = -90.0")
    stderr = cli("render", path, "--cpu", "-o", tmp_path / "x.png", check=False).stderr
    assert error.value.field == "spheres[0].radius"
    assert str(error.value) == f"{cornell}: spheres[0].radius: {error.value.message}"
    assert error.value.message in stderr
    assert error.value.line is None
    assert scene == glint.load(cornell)
    with pytest.raises(glint.SceneError, match=r"materials\.white\.color"):
        scene.materials["white"].color = (0.5, 0.5)
    with pytest.raises(glint.SceneError, match="eye"):
        scene.camera.eye = scene.camera.target
    assert scene == glint.load(cornell)


def test_missing_fields_and_read_only_settings(cornell):
    scene = glint.load(cornell)
    with pytest.raises(AttributeError, match="no table 'cameras'"):
        scene.cameras
    with pytest.raises(KeyError, match="no field 'silver'"):
        scene.materials["silver"]
    with pytest.raises(IndexError, match="out of range"):
        scene.spheres[99]
    with pytest.raises(AttributeError, match="read-only"):
        scene.spp = 4


def test_scene_error_attributes(cornell, tmp_path):
    bad = edited_file(tmp_path, cornell, "radius = 90.0", "radius = -90.0")
    line = bad.read_text().splitlines().index("radius = -90.0") + 1
    with pytest.raises(glint.SceneError) as error:
        glint.load(bad)
    e = error.value
    assert (e.path, e.line, e.field) == (str(bad), line, "spheres[0].radius")
    assert str(e) == f"{bad}:{line}:{e.column}: spheres[0].radius: {e.message}"


def test_a_scene_with_array_meshes_stays_editable(root):
    """Array meshes live in PLY files kept as long as the scene, which reads them again at
    each edit: an edit long after load_dict still finds them."""
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=np.float64)
    indices = np.array([[0, 1, 2], [1, 3, 2]])
    as_dict = glint.load(root / "scenes" / "cornell.toml").to_dict()
    as_dict["meshes"] = [
        {"vertices": vertices * 100 + 200, "indices": indices, "material": "white"}
    ]
    scene = glint.load_dict(as_dict)
    assert repr(scene).endswith(" 2 triangles>")
    scene.camera.vfov = 30.0
    assert repr(scene).endswith(" 2 triangles>")
    scene.meshes[0] = {"vertices": vertices * 50 + 200, "indices": indices[:1], "material": "red"}
    assert scene.meshes[0].material == "red"
    assert repr(scene).endswith(" 1 triangles>")
    with pytest.raises(ValueError, match="vertices and indices go together"):
        scene.meshes[0] = {"vertices": vertices, "material": "red"}


def test_scene_error_parts_default_to_none(tmp_path):
    assert glint.SceneError("x").field is None and glint.SceneError("x").line is None
    missing = tmp_path / "missing.toml"
    with pytest.raises(glint.SceneError) as error:
        glint.load(missing)
    assert (error.value.path, error.value.line, error.value.field) == (str(missing), None, None)
