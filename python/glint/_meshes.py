"""Meshes given as arrays in a scene dictionary: written as binary PLY files, which glint's
own reader then reads as it reads any scene's meshes (so an array mesh is checked, and
becomes the same triangles, as the same mesh from a file). Written by hand: a PLY of
triangles is a header and two arrays, and NumPy writes the arrays."""

import os
import tempfile

import numpy as np


def has_arrays(mesh):
    return isinstance(mesh, dict) and ("vertices" in mesh or "indices" in mesh)


def _write_ply(path, vertices, indices, at):
    """A binary PLY of the mesh, in the layout of scenes/models/bunny.ply."""
    vertices = np.asarray(vertices, dtype=np.float32)
    indices = np.asarray(indices)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"{at}.vertices: expected an N×3 array, got shape {vertices.shape}")
    if indices.ndim != 2 or indices.shape[1] != 3 or indices.dtype.kind not in "iu":
        raise ValueError(
            f"{at}.indices: expected an M×3 integer array, got shape {indices.shape} of {indices.dtype}"
        )
    if indices.size and (indices.min() < 0 or indices.max() >= len(vertices)):
        raise ValueError(
            f"{at}.indices: {indices.min()}..{indices.max()} is out of range for {len(vertices)} vertices"
        )
    faces = np.empty(len(indices), dtype=[("count", "u1"), ("index", "<i4", (3,))])
    faces["count"] = 3
    faces["index"] = indices
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(indices)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertices.astype("<f4").tobytes())
        f.write(faces.tobytes())


def as_files(table, folder):
    """`table` with every array mesh replaced by a PLY file written into `folder` (a
    TemporaryDirectory made when first needed and returned: the files must outlive the
    scene, which reads them again when edited). Returns (table, folder)."""
    meshes = table.get("meshes") if isinstance(table, dict) else None
    if not (isinstance(meshes, (list, tuple)) and any(has_arrays(m) for m in meshes)):
        return table, folder
    written = []
    for i, mesh in enumerate(meshes):
        at = f"scene.meshes[{i}]"
        if not has_arrays(mesh):
            written.append(mesh)
            continue
        if "file" in mesh:
            raise ValueError(f"{at}: give file, or vertices and indices, not both")
        if "vertices" not in mesh or "indices" not in mesh:
            raise ValueError(f"{at}: vertices and indices go together")
        if folder is None:
            folder = tempfile.TemporaryDirectory(prefix="glint-meshes-")
        # A new name each time: the scene before an edit keeps its files if the edit fails.
        fd, file = tempfile.mkstemp(suffix=".ply", dir=folder.name)
        os.close(fd)
        _write_ply(file, mesh["vertices"], mesh["indices"], at)
        rest = {k: v for k, v in mesh.items() if k not in ("vertices", "indices")}
        written.append({"file": file, **rest})
    return {**table, "meshes": written}, folder
