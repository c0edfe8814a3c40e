"""Scenes: loading (a file, TOML text, a dictionary) and editing.

A Scene holds the validated scene the renderer takes and the TOML structure it came from.
Its tables read as attributes or items and can be assigned to:

    scene.camera.eye = (0, 1, 5)
    scene.materials["white"].color = (0.5, 0.5, 0.5)
    scene.spheres[0].radius = 80
    scene.render.spp                  # 64

Each assignment edits a copy of the structure and validates it again as glint render would
read it; a bad value raises glint.SceneError naming the field, and leaves the scene as it was.
"""

import copy
import os

from . import _glint, _meshes
from ._glint import SceneError


def _dotted(at):
    out = "scene"
    for key in at:
        out += f"[{key}]" if isinstance(key, int) else f".{key}"
    return out


def _wrap(scene, at, value):
    """A view for a table or an array of tables, a copy of anything else (so changing what
    was read does not change the scene behind its back)."""
    if isinstance(value, dict):
        return Table(scene, at)
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return TableArray(scene, at)
    return copy.deepcopy(value)


class Table:
    """A table of a scene (camera, render, a material, a sphere, ...): its fields read and
    assign as attributes or items."""

    __slots__ = ("_scene", "_at")

    def __init__(self, scene, at):
        object.__setattr__(self, "_scene", scene)
        object.__setattr__(self, "_at", at)

    def _value(self):
        return self._scene._lookup(self._at)

    def __getitem__(self, key):
        table = self._value()
        if key not in table:
            raise KeyError(f"{_dotted(self._at)} has no field {key!r} (it has {', '.join(table)})")
        return _wrap(self._scene, self._at + (key,), table[key])

    def __setitem__(self, key, value):
        self._scene._edit(self._at + (key,), value)

    def __delitem__(self, key):
        self._scene._edit(self._at + (key,), _DELETE)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(e.args[0]) from None

    def __setattr__(self, name, value):
        self[name] = value

    def __delattr__(self, name):
        del self[name]

    def __contains__(self, key):
        return key in self._value()

    def __iter__(self):
        return iter(list(self._value()))

    def __len__(self):
        return len(self._value())

    def keys(self):
        return list(self._value())

    def to_dict(self):
        """A copy of the table as a plain dict."""
        return copy.deepcopy(self._value())

    def __eq__(self, other):
        other = other.to_dict() if isinstance(other, Table) else other
        return self._value() == other

    __hash__ = None

    def __repr__(self):
        return f"<glint.Table {_dotted(self._at)} {self._value()!r}>"


class TableArray:
    """An array of tables ([[spheres]], [[quads]], [[meshes]], [[lights]]): items are
    Tables; assign a dict to an item to replace it, append one to add it."""

    __slots__ = ("_scene", "_at")

    def __init__(self, scene, at):
        self._scene = scene
        self._at = at

    def _value(self):
        return self._scene._lookup(self._at)

    def _index(self, i):
        n = len(self._value())
        if not isinstance(i, int) or not -n <= i < n:
            raise IndexError(f"{_dotted(self._at)}: index {i!r} out of range for {n} tables")
        return i % n

    def __getitem__(self, i):
        i = self._index(i)
        return Table(self._scene, self._at + (i,))

    def __setitem__(self, i, value):
        self._scene._edit(self._at + (self._index(i),), value)

    def __delitem__(self, i):
        self._scene._edit(self._at + (self._index(i),), _DELETE)

    def append(self, value):
        self._scene._edit(self._at + (len(self._value()),), value)

    def __len__(self):
        return len(self._value())

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def to_list(self):
        """A copy of the tables as a list of plain dicts."""
        return copy.deepcopy(self._value())

    def __repr__(self):
        return f"<glint.TableArray {_dotted(self._at)}: {len(self)} tables>"


_DELETE = object()


class Scene:
    """A validated scene, from glint.load, glint.load_string or glint.load_dict.

    Its top-level tables (camera, render, materials, spheres, quads, meshes, lights,
    environment) read and assign as attributes; see the module's docstring. to_dict() gives
    the whole structure, for glint.load_dict. Scenes are equal when their validated contents
    are (the name, its path's stem, included).
    """

    __slots__ = ("_compiled", "_table", "_meshes")

    def __init__(self, compiled, table=None, meshes=None):
        object.__setattr__(self, "_compiled", compiled)
        # The TOML structure: read from the compiled scene when first needed.
        object.__setattr__(self, "_table", table)
        # The TemporaryDirectory holding meshes given as arrays (None: there are none).
        object.__setattr__(self, "_meshes", meshes)

    @property
    def path(self):
        """The file the scene was read from, or the path given to load_string/load_dict."""
        return self._compiled.path

    @property
    def name(self):
        """The scene's name: its path's stem."""
        return self._compiled.name

    @property
    def width(self):
        return self._compiled.width

    @property
    def height(self):
        return self._compiled.height

    @property
    def spp(self):
        return self._compiled.spp

    @property
    def seed(self):
        return self._compiled.seed

    @property
    def max_bounces(self):
        return self._compiled.max_bounces

    def _structure(self):
        if self._table is None:
            object.__setattr__(self, "_table", self._compiled.table())
        return self._table

    def _lookup(self, at):
        value = self._structure()
        for key in at:
            value = value[key]
        return value

    def _edit(self, at, value):
        """Sets (or with _DELETE removes) the field at `at` in a copy of the structure and
        makes that the scene, once it validates."""
        table = copy.deepcopy(self._structure())
        parent = table
        for key in at[:-1]:
            parent = parent[key]
        key = at[-1]
        if value is _DELETE:
            del parent[key]
        elif isinstance(parent, list) and key == len(parent):
            parent.append(value)
        else:
            parent[key] = value
        table, meshes = _meshes.as_files(table, self._meshes)
        try:
            compiled = _glint.load_dict(table, path=os.fspath(self.path))
        except SceneError as e:
            # The line numbers would be those of TOML text the user never saw: name the field.
            where = f"{e.field}: " if e.field else ""
            error = SceneError(f"{e.path}: {where}{e.message}")
            error.path, error.line, error.column = e.path, None, None
            error.field, error.message = e.field, e.message
            raise error from None
        compiled.adopt_renderer(self._compiled)
        object.__setattr__(self, "_compiled", compiled)
        # Read back from the TOML it was validated as: tuples and arrays become lists.
        object.__setattr__(self, "_table", None)
        object.__setattr__(self, "_meshes", meshes)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        table = self._structure()
        if name not in table:
            raise AttributeError(
                f"the scene has no table {name!r} (it has {', '.join(table)}); "
                f"add one with scene[{name!r}] = {{...}}"
            )
        return _wrap(self, (name,), table[name])

    def __setattr__(self, name, value):
        if name in type(self).__dict__:
            raise AttributeError(f"{name} is read-only: set scene.render.{name} instead")
        self._edit((name,), value)

    def __getitem__(self, name):
        try:
            return self.__getattr__(name)
        except AttributeError as e:
            raise KeyError(e.args[0]) from None

    def __setitem__(self, name, value):
        self._edit((name,), value)

    def __delitem__(self, name):
        self._edit((name,), _DELETE)

    def __contains__(self, name):
        return name in self._structure()

    def to_dict(self):
        """The scene's TOML structure as dicts and lists (meshes given as arrays appear as
        the PLY files they were written to)."""
        return copy.deepcopy(self._structure())

    def __eq__(self, other):
        if not isinstance(other, Scene):
            return NotImplemented
        return self._compiled == other._compiled

    __hash__ = None

    def __repr__(self):
        return repr(self._compiled)


def load(path, camera=None):
    """load(path, camera=None) -> Scene

    Reads and validates a scene file (TOML) as `glint render` does, or builds the scene of a
    model file (.glb, .gltf, .obj, .ply) as `glint render model.glb` does: the file's camera
    (camera=N is --camera N) or one framing the model, its lights, the studio environment;
    its structure is the scene file `--print-scene` writes (a framing camera frames the
    default 512-pixel image: render's width and height resize it without framing again,
    where `glint render model.glb --width W --height H` frames for W×H). Raises glint.SceneError with the
    CLI's message (file, line and column, field) for a bad scene; the exception's path,
    line, column, field and message attributes hold the parts."""
    return Scene(_glint.load(os.fspath(path), camera))


def load_string(text, path="<string>"):
    """load_string(text, path="<string>") -> Scene

    Parses and validates scene text (TOML). `path` names the text in error messages and gives
    the scene its name; relative mesh and texture files are found from its folder."""
    return Scene(_glint.load_string(text, os.fspath(path)))


def load_dict(scene, path="<dict>"):
    """load_dict(scene, path="<dict>") -> Scene

    A scene given as the TOML file's structure in Python: a dict of tables (camera, render,
    materials, ...), lists for arrays (of tables too), and str, int, float and bool values;
    NumPy arrays and scalars count as lists and numbers. It is written out as TOML and read by
    glint's own parser, so it is checked as a file is: a bad scene raises glint.SceneError
    with the CLI's message (its line numbers are those of the TOML text). `path` names the
    scene in messages and gives it its name; relative mesh and texture files are found from
    its folder.

    A mesh may give `vertices` (N×3) and `indices` (M×3, one triangle a row) as arrays in
    place of `file`: they are read as a PLY file of those triangles would be.
    """
    if not isinstance(scene, dict):
        raise ValueError(
            f"load_dict: the scene must be a dict (the TOML file's tables), got {type(scene).__name__}"
        )
    table, meshes = _meshes.as_files(scene, None)
    compiled = _glint.load_dict(table, path=os.fspath(path))
    return Scene(compiled, None, meshes)
