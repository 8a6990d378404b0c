"""A robot description's mesh files, found the way ROS finds them and made drawable by MuJoCo.

Real robots' descriptions name their meshes ``package://NAME/path``: the
file ``path`` of the ROS package ``NAME``.  :func:`resolve_mesh` looks for it
as ROS 2 does, in ``share/NAME`` under every prefix of ``AMENT_PREFIX_PATH``,
then as ROS 1 did, in ``ROS_PACKAGE_PATH``'s folders (each the package
itself, or a folder holding it); ``file://`` URIs and plain paths are files.
A mesh that cannot be found raises :class:`MeshError` naming the mesh and
where it was looked for.

MuJoCo reads STL, OBJ and its own MSH; most ROS robots draw Collada
(``.dae``) files, which it does not.  :func:`drawable_meshes` converts any
other format with ``trimesh`` (Collada through ``pycollada``) into STL files,
one per colour the file's materials give, so the colours are kept; the
conversions are cached by the file's content (``RTT_MESH_CACHE``, or
``~/.cache/ros-tank-tutorial/meshes``), so a restart does not redo them.
A file that is not a mesh (truncated, another format) raises
:class:`MeshError` with one line saying why.  A mesh over MuJoCo's limit of
:data:`MAX_FACES` triangles (its STL reader refuses more) is simplified to
that many (``trimesh``'s quadric decimation, ``fast-simplification``), and
the part says how many it had.

Any thread may call these functions; two processes converting the same file
at once each write their own temporary files and rename them into place.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import NamedTuple
from urllib.parse import unquote, urlparse

MUJOCO_FORMATS = (".stl", ".obj", ".msh")  # what MuJoCo's compiler reads itself
MAX_FACES = 200_000  # MuJoCo's STL reader takes at most this many triangles per file
CONVERTER_VERSION = 2  # bumped when a conversion's output changes: older cache entries are not used


class Part(NamedTuple):
    """One drawable file of a mesh: the file MuJoCo reads, its colour, and its triangles before simplifying."""

    path: Path
    rgba: tuple[float, ...] | None  # 0 to 1; None: the visual's own colour
    simplified_from: int | None = None  # the triangle count over MAX_FACES it had; None: drawn as it is


class MeshError(ValueError):
    """A mesh that cannot be drawn: not found, or not a mesh; the message is one line."""


def package_folders(name: str, environ: Mapping[str, str] | None = None) -> list[Path]:
    """Where ``package://name/`` may be, in the order ROS looks (existing or not)."""
    env = os.environ if environ is None else environ
    places = [Path(p) / "share" / name for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    for folder in (Path(p) for p in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p):
        places += [folder] if folder.name == name else [folder / name]
    return places


def resolve_mesh(uri: str, environ: Mapping[str, str] | None = None) -> Path:
    """The file a description's ``filename`` names.

    Raises:
        MeshError: a ``package://`` URI found nowhere (the message names the
            folders looked in), another URI scheme, or a missing file.
    """
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name, rest = parsed.netloc, unquote(parsed.path).lstrip("/")
        places = package_folders(name, environ)
        for folder in places:
            if (folder / rest).is_file():
                return folder / rest
        where = ", ".join(str(p) for p in places) or "nowhere: AMENT_PREFIX_PATH and ROS_PACKAGE_PATH are empty"
        raise MeshError(f"{uri}: not found (looked in {where})")
    if parsed.scheme == "file":
        path = Path(unquote(parsed.path))
    elif parsed.scheme == "" or len(parsed.scheme) == 1:  # a plain path (a Windows drive letter is no scheme)
        path = Path(uri)
    else:
        raise MeshError(f"{uri}: {parsed.scheme}:// names cannot be read here (package:// and file:// can)")
    if not path.is_file():
        raise MeshError(f"{uri}: no such file")
    return path


def cache_folder(environ: Mapping[str, str] | None = None) -> Path:
    env = os.environ if environ is None else environ
    if env.get("RTT_MESH_CACHE"):
        return Path(env["RTT_MESH_CACHE"])
    base = Path(env.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "ros-tank-tutorial" / "meshes"


def drawable_meshes(path: Path, cache: Path | None = None) -> list[Part]:
    """The :class:`Part` files MuJoCo draws the mesh file ``path`` with.

    A format MuJoCo reads is returned as it is, with no colour, once
    ``trimesh`` has read it (so a broken file is named here, not in MuJoCo's
    compiler) and found within :data:`MAX_FACES`.  Another format, or a
    larger mesh, is converted: one STL per colour its materials give (rgba,
    0 to 1), in the file's own frame and units, each simplified to
    :data:`MAX_FACES` triangles if it had more.

    Raises:
        MeshError: the file is not a mesh ``trimesh`` can read, or holds no triangles.
    """
    data = path.read_bytes()
    key = hashlib.sha256(data + f"|{path.suffix.lower()}|{CONVERTER_VERSION}".encode()).hexdigest()[:32]
    folder = (Path(cache) if cache else cache_folder()) / key
    index = folder / "parts.json"
    if index.is_file():
        parts = json.loads(index.read_text())
        if all((folder / p["file"]).is_file() for p in parts):
            return [_part(folder, p) for p in parts]
    scene = _load(path, data)
    if path.suffix.lower() in MUJOCO_FORMATS and _faces(scene) <= MAX_FACES:
        return [Part(path, None)]  # checked: MuJoCo's compiler would fail the whole robot on it
    by_colour: dict[tuple | None, list] = {}
    for mesh in scene.dump(concatenate=False) if hasattr(scene, "dump") else [scene]:
        if len(getattr(mesh, "faces", ())) == 0:
            continue
        by_colour.setdefault(_colour(mesh), []).append(mesh)
    if not by_colour:
        raise MeshError(f"{path}: no triangles in it")
    import trimesh

    folder.mkdir(parents=True, exist_ok=True)
    parts = []
    for i, (rgba, meshes) in enumerate(sorted(by_colour.items(), key=lambda kv: str(kv[0]))):
        name = f"part{i}.stl"
        tmp = folder / f".{name}.{os.getpid()}"
        mesh, faces = trimesh.util.concatenate(meshes), None
        try:
            if len(mesh.faces) > MAX_FACES:
                faces, mesh = len(mesh.faces), mesh.simplify_quadric_decimation(face_count=MAX_FACES)
            mesh.export(tmp, file_type="stl")
        except Exception as exc:  # noqa: BLE001 - a mesh the simplifier or writer cannot take: said, not raised
            raise MeshError(f"{path}: cannot be made drawable ({type(exc).__name__}: {exc})") from None
        os.replace(tmp, folder / name)
        parts.append({"file": name, "rgba": list(rgba) if rgba else None, "simplified_from": faces})
    tmp = folder / f".parts.json.{os.getpid()}"
    tmp.write_text(json.dumps(parts))
    os.replace(tmp, index)
    return [_part(folder, p) for p in parts]


def _part(folder: Path, entry: dict) -> Part:
    return Part(folder / entry["file"], tuple(entry["rgba"]) if entry["rgba"] else None, entry["simplified_from"])


def _faces(scene) -> int:
    return sum(
        len(getattr(m, "faces", ())) for m in (scene.geometry.values() if hasattr(scene, "geometry") else [scene])
    )


def _load(path: Path, data: bytes):
    import io

    import trimesh

    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=path.suffix.lower().lstrip("."), force="scene")
    except Exception as exc:  # noqa: BLE001 - every reader's own error: a broken or foreign file
        raise MeshError(f"{path}: not a {path.suffix} mesh trimesh can read ({type(exc).__name__}: {exc})") from None
    if hasattr(loaded, "geometry") and not loaded.geometry and path.suffix.lower() == ".dae":
        loaded = _without_textures(path, data) or loaded
    if hasattr(loaded, "geometry") and not loaded.geometry:
        raise MeshError(f"{path}: no triangles in it")
    return loaded


def _without_textures(path: Path, data: bytes):
    """The Collada file read again without its texture parameters, or None.

    ``pycollada`` drops a material whose texture names a surface it cannot
    find (ANYmal B's feet), and ``trimesh`` then drops the triangles bound to
    that material.  Without the texture parameters the materials, with their
    colours, and the triangles load.
    """
    import io

    import trimesh
    from lxml import etree

    try:
        root = etree.fromstring(data, parser=etree.XMLParser(resolve_entities=False))
        for param in list(root.iter("{*}newparam")):
            param.getparent().remove(param)
        loaded = trimesh.load(io.BytesIO(etree.tostring(root)), file_type="dae", force="scene")
    except Exception:  # noqa: BLE001 - as broken as before: the caller names it
        return None
    return loaded if loaded.geometry else None


def _colour(mesh) -> tuple[float, ...] | None:
    """The mesh's one colour (rgba, 0 to 1) from its material or face colours, or None."""
    visual = getattr(mesh, "visual", None)
    if visual is None:
        return None
    try:
        if visual.kind == "texture" and getattr(visual, "material", None) is not None:
            rgba = visual.material.main_color
        elif visual.kind in ("face", "vertex"):
            rgba = visual.main_color
        else:
            return None
    except Exception:  # noqa: BLE001 - a material trimesh cannot summarise: drawn in the visual's colour
        return None
    return tuple(round(float(c) / 255.0, 4) for c in rgba[:4])
