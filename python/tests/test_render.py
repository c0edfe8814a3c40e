"""A render from Python is the CLI's render: the same bytes on the CPU, the same statistics."""

import json
import os

import numpy as np
import pytest

import glint

# Tiny renders: the point is equality, not convergence.
SETTINGS = dict(width=20, height=16, spp=5, seed=3, max_bounces=4)


def cli_flags(settings):
    flags = []
    for key, value in settings.items():
        flags += [f"--{key.replace('_', '-')}", value]
    return flags


def test_cpu_render_equals_the_cli_exr_bit_for_bit(cli, cornell, tmp_path):
    out, var = tmp_path / "cli.exr", tmp_path / "cli-var.exr"
    cli("render", cornell, "--cpu", *cli_flags(SETTINGS), "-o", out, "--variance", var)
    result = glint.render(glint.load(cornell), device="cpu", variance=True, **SETTINGS)
    assert result.image.dtype == np.float32
    assert result.image.shape == (16, 20, 3)
    assert result.image.mean() > 0
    # Bit for bit: compared as integers, so even NaNs or -0.0 would have to match.
    assert np.array_equal(result.image.view(np.uint32), glint.read(out).view(np.uint32))
    assert np.array_equal(result.variance.view(np.uint32), glint.read(var).view(np.uint32))
    assert result.stats["spp"] == 5
    assert result.stats["stopped_by"] == "spp"
    assert result.stats["device"] == "cpu"


def test_bdpt_render_equals_the_cli_exr_bit_for_bit(cli, root, tmp_path):
    scene = root / "scenes" / "cornell-glass.toml"
    out, var = tmp_path / "cli.exr", tmp_path / "cli-var.exr"
    settings = dict(SETTINGS, integrator="bdpt")
    cli("render", scene, "--cpu", *cli_flags(settings), "-o", out, "--variance", var)
    # device="auto" renders bdpt on the CPU reference, as the command does without --gpu.
    result = glint.render(glint.load(scene), variance=True, **settings)
    assert result.stats["integrator"] == "bdpt"
    assert result.stats["device"] == "cpu"
    assert np.array_equal(result.image.view(np.uint32), glint.read(out).view(np.uint32))
    # The variance from batch means (1, 1, 2 and 1 samples at 5 spp), as the command's.
    assert result.variance.mean() > 0
    assert np.array_equal(result.variance.view(np.uint32), glint.read(var).view(np.uint32))
    assert result.stats["relative_error"] > 0
    path = glint.render(glint.load(scene), device="cpu", full=True, **dict(settings, integrator="path"))
    assert path.stats["integrator"] == "path"
    assert not np.array_equal(path.image, result.image)
    with pytest.raises(ValueError, match="integrator"):
        glint.render(glint.load(scene), integrator="mlt")


def test_render_returns_a_plain_array_unless_asked_for_more(cornell):
    img = glint.render(glint.load(cornell), device="cpu", **SETTINGS)
    assert isinstance(img, np.ndarray) and img.shape == (16, 20, 3)
    img[0, 0] = 1.0  # writable


def test_a_different_seed_gives_a_different_image(cornell):
    scene = glint.load(cornell)
    a = glint.render(scene, device="cpu", **SETTINGS)
    b = glint.render(scene, device="cpu", **{**SETTINGS, "seed": 4})
    assert not np.array_equal(a, b)


def test_aovs(cornell):
    result = glint.render(
        glint.load(cornell), device="cpu", aovs=("albedo", "normal"), **SETTINGS
    )
    assert result.albedo.shape == result.normal.shape == (16, 20, 3)
    assert result.depth is None and result.variance is None
    # The walls are diffuse with albedo ≤ 0.73; normals are at most unit length.
    assert 0 < result.albedo.max() <= 1
    assert np.all(np.linalg.norm(result.normal, axis=2) <= 1 + 1e-5)


def test_write_and_read_round_trip(cornell, tmp_path):
    img = glint.render(glint.load(cornell), device="cpu", **SETTINGS)
    glint.write(tmp_path / "a.exr", img)
    assert np.array_equal(glint.read(tmp_path / "a.exr"), img)
    glint.write(tmp_path / "a.png", img, tonemap="agx", exposure=1.0)
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compare_gives_the_cli_figures(cli, cornell, tmp_path):
    scene = glint.load(cornell)
    a = glint.render(scene, device="cpu", variance=True, **SETTINGS)
    b = glint.render(scene, device="cpu", variance=True, **{**SETTINGS, "seed": 9})
    paths = {}
    for name, image in [("a", a.image), ("b", b.image), ("va", a.variance), ("vb", b.variance)]:
        paths[name] = tmp_path / f"{name}.exr"
        glint.write(paths[name], image)
    ours = glint.compare(a.image, b.image, variance_a=a.variance, variance_b=b.variance)
    theirs = json.loads(
        cli(
            "compare", paths["a"], paths["b"], "--variance-a", paths["va"],
            "--variance-b", paths["vb"], "--json",
        ).stdout
    )
    for key in ["rmse", "relative_mse", "mean_a", "mean_b", "max_difference", "z_test"]:
        assert ours[key] == theirs[key], key
    assert glint.compare(a.image, a.image)["rmse"] == 0


def test_gpu_render_is_repeatable_and_close_to_the_cpu(cornell):
    """The GPU (lavapipe in CI) through the cached renderer: a second render of the same
    scene and settings reuses it and gives the same image."""
    scene = glint.load(cornell)
    try:
        first = glint.render(scene, device="gpu", full=True, **SETTINGS)
    except RuntimeError as e:
        pytest.skip(f"no GPU: {e}")
    second = glint.render(scene, device="gpu", full=True, **SETTINGS)
    assert first.stats["device"] != "cpu"
    assert np.array_equal(first.image, second.image)
    cpu = glint.render(scene, device="cpu", **SETTINGS)
    # The GPU traces the same paths as the CPU reference; only float rounding differs.
    assert np.allclose(first.image, cpu, rtol=1e-3, atol=1e-3)


def gpu_or_skip(scene, **settings):
    try:
        return glint.render(scene, device="gpu", full=True, **settings)
    except RuntimeError as e:
        pytest.skip(f"no GPU: {e}")


def test_a_second_gpu_render_reuses_the_kernel_and_equals_a_fresh_one(cornell):
    """The scene's renderer and compiled kernel serve its next renders where only the camera
    or the [render] settings changed; the image is the one a fresh renderer gives."""
    scene = glint.load(cornell)
    first = gpu_or_skip(scene, **SETTINGS)
    assert not first.stats["kernel_reused"]
    other = {**SETTINGS, "seed": 7, "spp": 3, "max_bounces": 2}
    second = glint.render(scene, device="gpu", full=True, **other)
    assert second.stats["kernel_reused"]
    assert np.array_equal(second.image, glint.render(glint.load(cornell), device="gpu", **other))
    scene.camera.eye = (278, 278, -600)
    moved = glint.render(scene, device="gpu", full=True, **SETTINGS)
    assert moved.stats["kernel_reused"]
    assert np.array_equal(moved.image, glint.render(glint.load_dict(scene.to_dict(), path=str(cornell)), device="gpu", **SETTINGS))
    # Another image size or other materials need another renderer.
    assert not glint.render(scene, device="gpu", full=True, **{**SETTINGS, "width": 8}).stats["kernel_reused"]
    scene.materials["white"].color = (0.5, 0.5, 0.5)
    assert not glint.render(scene, device="gpu", full=True, **{**SETTINGS, "width": 8}).stats["kernel_reused"]


def test_denoise(cornell):
    try:
        result = glint.render(glint.load(cornell), device="cpu", denoise=True, **SETTINGS)
    except RuntimeError as e:
        if os.environ.get("GLINT_REQUIRE_OIDN"):
            raise
        assert "Open Image Denoise" in str(e)
        pytest.skip(str(e))
    plain = glint.render(glint.load(cornell), device="cpu", **SETTINGS)
    # The raw mean is the render's (AOVs leave it bit for bit the same); the image is OIDN's.
    assert np.array_equal(result.raw, plain)
    assert result.image.shape == plain.shape and np.isfinite(result.image).all()
    assert not np.array_equal(result.image, plain)
    assert result.stats["denoise_seconds"] > 0


def test_a_model_file_is_a_scene_as_on_the_command_line(cli, root, tmp_path):
    """glint.load("model.gltf") builds the scene `glint render model.gltf` renders (the file's
    camera, its lights, the studio environment): the same bytes on the CPU; its structure is
    the scene file --print-scene writes, so it edits like any scene."""
    model = root / "tests" / "models" / "lights-cameras.gltf"
    settings = dict(width=16, height=12, spp=2, seed=1, max_bounces=3)
    out = tmp_path / "model.exr"
    cli("render", model, "--cpu", "--camera", 1, *cli_flags(settings), "-o", out)
    scene = glint.load(model, camera=1)
    image = glint.render(scene, device="cpu", **settings)
    assert np.array_equal(image.view(np.uint32), glint.read(out).view(np.uint32))
    assert glint.load(model) != scene  # camera 0
    scene.camera.vfov = 20.0
    assert not np.array_equal(glint.render(scene, device="cpu", **settings), image)
    with pytest.raises(glint.SceneError, match="camera applies to a model file"):
        glint.load(root / "scenes" / "cornell.toml", camera=1)


def test_light_sampler_kwarg_picks_the_tree_or_power(cornell):
    tree = glint.render(glint.load(cornell), device="cpu", full=True, light_sampler="tree", **SETTINGS)
    assert tree.stats["light_sampler"] == "tree"
    power = glint.render(glint.load(cornell), device="cpu", full=True, light_sampler="power", **SETTINGS)
    assert power.stats["light_sampler"] == "power"
    with pytest.raises(ValueError, match="light_sampler"):
        glint.render(glint.load(cornell), light_sampler="bvh")
