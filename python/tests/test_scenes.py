"""Scenes from files, text and dictionaries; errors are the CLI's."""

import re

import numpy as np
import pytest

import glint

try:
    import tomllib  # Python 3.11+: a TOML reader independent of glint's
except ImportError:  # the package needs only 3.9; there, glint's own reading of the file
    tomllib = None


def read_toml(path):
    """The scene file's structure as dicts and lists."""
    if tomllib is None:
        return glint.load(path).to_dict()
    with open(path, "rb") as f:
        return tomllib.load(f)


def test_load_dict_equals_the_toml_file(cornell):
    as_dict = read_toml(cornell)
    from_file = glint.load(cornell)
    assert glint.load_dict(as_dict, path=str(cornell)) == from_file
    assert glint.load_string(cornell.read_text(), path=str(cornell)) == from_file
    # Without a path the name differs (it is the file's stem), and so does the scene.
    assert glint.load_dict(as_dict) != from_file


def test_load_dict_takes_numpy_values_and_renders_as_the_file(cornell):
    as_dict = read_toml(cornell)
    as_dict["camera"]["eye"] = np.array(as_dict["camera"]["eye"], dtype=np.float64)
    as_dict["render"]["spp"] = np.int64(as_dict["render"]["spp"])
    scene = glint.load_dict(as_dict, path=str(cornell))
    assert scene == glint.load(cornell)
    settings = dict(width=12, height=10, spp=2, device="cpu")
    assert np.array_equal(glint.render(scene, **settings), glint.render(glint.load(cornell), **settings))


def test_edited_dict_changes_the_render(cornell):
    as_dict = read_toml(cornell)
    settings = dict(width=12, height=10, spp=2, device="cpu")
    before = glint.render(glint.load_dict(as_dict), **settings)
    as_dict["materials"]["light"]["strength"] = 30.0
    after = glint.render(glint.load_dict(as_dict), **settings)
    assert after.mean() > 1.5 * before.mean()


def scene_error_and_cli_message(cli, path):
    with pytest.raises(glint.SceneError) as error:
        glint.load(path)
    result = cli("render", path, "--cpu", "-o", path.with_suffix(".png"), check=False)
    assert result.returncode == 2
    return str(error.value), result.stderr


def test_a_bad_scene_raises_scene_error_with_the_cli_message(cli, cornell, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(cornell.read_text().replace("radius = 90.0", "radius = -90.0", 1))
    message, stderr = scene_error_and_cli_message(cli, bad)
    assert isinstance(glint.SceneError("x"), ValueError)
    assert re.match(rf"{re.escape(str(bad))}:\d+:\d+: spheres\[0\]\.radius: ", message), message
    assert message in stderr


def test_a_toml_syntax_error_and_a_missing_file(cli, tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text("[camera\n")
    message, stderr = scene_error_and_cli_message(cli, broken)
    assert message.startswith(f"{broken}:1:") and message in stderr
    missing = tmp_path / "missing.toml"
    message, stderr = scene_error_and_cli_message(cli, missing)
    assert message.startswith(str(missing)) and message in stderr


def test_dict_and_string_errors_name_the_field(cornell):
    text = cornell.read_text().replace("eye = [278.0, 278.0, -800.0]", "eye = 1")
    line = text.splitlines().index("eye = 1") + 1
    with pytest.raises(glint.SceneError, match=rf"^<string>:{line}:\d+: "):
        glint.load_string(text)
    with pytest.raises(glint.SceneError, match=r"^<dict>"):
        glint.load_dict({"camera": {"eye": [0, 0, 0]}})
    with pytest.raises(ValueError, match=r"scene\.camera\.eye\[0\]: a NoneType"):
        glint.load_dict({"camera": {"eye": [None, 0, 0]}})
    with pytest.raises(ValueError, match="must be a dict"):
        glint.load_dict([1, 2])
    looping = []
    looping.append(looping)
    with pytest.raises(ValueError, match="nested more than"):
        glint.load_dict({"a": looping})


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        (dict(spp=0), r"spp: must be in 1\.\."),
        (dict(spp=2.5), r"spp: expected an integer"),
        (dict(width=-1), r"width: must be in 1\.\."),
        (dict(max_bounces=5000), r"max_bounces: must be in 0\.\."),
        (dict(seed=2**32), r"seed: must be in 0\.\."),
        (dict(device="tpu"), r"device: expected"),
        (dict(traversal="rt"), r"traversal: expected"),
        (dict(aovs=("colour",)), r"aovs: expected"),
        (dict(light_sampling="maybe"), r"light_sampling: expected"),
        (dict(time_limit=-1), r"time_limit: must be"),
        (dict(width=16384, height=16384), r"too large to hold"),
    ],
)
def test_bad_arguments_raise_value_error(cornell, kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        glint.render(glint.load(cornell), **{"device": "cpu", **kwargs})


def test_bad_images_raise_value_error(tmp_path):
    with pytest.raises(ValueError, match="H×W×3"):
        glint.write(tmp_path / "x.exr", np.zeros((4, 4)))
    with pytest.raises(ValueError, match="unknown image format"):
        glint.write(tmp_path / "x.jpg", np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match="tonemap"):
        glint.write(tmp_path / "x.png", np.zeros((4, 4, 3)), tonemap="filmic")
    with pytest.raises(ValueError, match="sizes differ"):
        glint.compare(np.zeros((4, 4, 3)), np.zeros((4, 5, 3)))
    with pytest.raises(ValueError, match="go together"):
        glint.compare(np.zeros((4, 4, 3)), np.zeros((4, 4, 3)), variance_a=np.zeros((4, 4, 3)))


def read_ply(path):
    """The bunny's vertices and triangles, from its binary PLY (x, y, z floats; uchar-int lists)."""
    data = path.read_bytes()
    header_end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:header_end].decode().split("\n")
    count = {line.split()[1]: int(line.split()[2]) for line in header if line.startswith("element")}
    vertices = np.frombuffer(data, dtype="<f4", count=3 * count["vertex"], offset=header_end)
    faces = np.frombuffer(
        data, dtype=[("n", "u1"), ("i", "<i4", (3,))], count=count["face"],
        offset=header_end + vertices.nbytes,
    )
    assert np.all(faces["n"] == 3)
    return vertices.reshape(-1, 3), faces["i"]


def test_a_mesh_from_numpy_arrays_equals_the_same_mesh_from_a_ply(root):
    path = root / "scenes" / "bunny.toml"
    as_dict = read_toml(path)
    vertices, indices = read_ply(root / "scenes" / "models" / "bunny.ply")
    mesh = as_dict["meshes"][0]
    del mesh["file"]
    mesh["vertices"], mesh["indices"] = vertices.astype(np.float64), indices.astype(np.int64)
    from_arrays = glint.load_dict(as_dict, path=str(path))
    assert from_arrays == glint.load(path)
    mesh["indices"] = indices[:, ::-1].copy()  # the other winding: different normals
    assert glint.load_dict(as_dict, path=str(path)) != glint.load(path)
    mesh["indices"] = indices + len(vertices)
    with pytest.raises(ValueError, match=r"meshes\[0\]\.indices: .* out of range"):
        glint.load_dict(as_dict, path=str(path))
