"""glint from Python: load scenes (files, TOML text or dictionaries), edit them, render them
to NumPy arrays on the GPU or the CPU reference, write and compare images.

    import glint
    scene = glint.load("scenes/cornell.toml")
    img = glint.render(scene, spp=64)                 # float32 array, H×W×3, linear radiance
    scene.camera.eye = (278, 278, -600)               # edit, render again
    glint.write("out.png", img, tonemap="agx")

Everything is done by the same Rust crate as the `glint` command: scenes are validated and
rendered by the CLI's code, with its messages, and a CPU render equals the CLI's bit for bit.
"""

from ._glint import SceneError, compare, read, write
from .rendering import AOV_NAMES, RenderResult, render
from .scene import Scene, Table, TableArray, load, load_dict, load_string

# A SceneError's parts, where it has them (a scene file's error has all; one found while
# laying the scene out for a render has only its message).
SceneError.path = SceneError.line = SceneError.column = SceneError.field = None
SceneError.message = None

__all__ = [
    "AOV_NAMES",
    "Scene",
    "SceneError",
    "RenderResult",
    "Table",
    "TableArray",
    "load",
    "load_string",
    "load_dict",
    "render",
    "write",
    "read",
    "compare",
]
