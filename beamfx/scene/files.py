"""The files a scene is made of: the scene file itself and the files it names.

A scene file is read as UTF-8 TOML of bounded size and nesting; a file it names (a gmsh curve)
is a regular file inside the scene file's folder (``..`` may not leave it, nor may a symbolic
link), of bounded size, unless ``[limits] files_outside = true``; devices, FIFOs and folders
are refused even then (``/dev/zero`` would be read forever).
"""

import os
import stat
import tomllib
from pathlib import Path

from .table import SceneError

MAX_SCENE_MB = 4  # larger is refused unread (tomllib reads about 1 MB/s; scenes are kB)
MAX_NESTING = 32  # tables and arrays within each other (tomllib recurses on them)


def _nesting(data):
    """Depth of nested tables and arrays of parsed TOML data, without recursion."""
    deepest, stack = 0, [(data, 0)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if deepest > MAX_NESTING:
            break
        if isinstance(node, dict):
            stack.extend((v, depth + 1) for v in node.values())
        elif isinstance(node, list):
            stack.extend((v, depth + 1) for v in node)
    return deepest


def read_toml(path: str | os.PathLike) -> dict:
    """The TOML data of the scene file at ``path``.

    Raises:
        SceneError: naming the file, if it is missing, not a regular file, too large, not
            UTF-8, not TOML, or nested too deeply.
    """
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise SceneError(f"{path}: no such scene file") from None
    except OSError as e:
        raise SceneError(f"{path}: cannot read the scene file: {e.strerror}") from None
    if not stat.S_ISREG(info.st_mode):
        raise SceneError(f"{path}: not a regular file (a scene is a TOML text file)")
    if info.st_size > MAX_SCENE_MB * 1e6:
        raise SceneError(
            f"{path}: {info.st_size / 1e6:.0f} MB; a scene file has at most {MAX_SCENE_MB} MB"
        )
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as e:
        raise SceneError(f"{path}: not UTF-8 text (byte {e.start}: {e.reason})") from None
    except OSError as e:
        raise SceneError(f"{path}: cannot read the scene file: {e.strerror}") from None
    return parse_toml(text, path)


def parse_toml(text: str, path: str | os.PathLike = "<scene>") -> dict:
    """The TOML data of ``text`` (the contents of ``path``), nesting bounded."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{path}: not valid TOML: {e}") from None
    except (RecursionError, MemoryError):
        raise SceneError(
            f"{path}: not valid TOML here: tables or arrays nested too deeply "
            f"(at most {MAX_NESTING} levels)"
        ) from None
    if _nesting(data) > MAX_NESTING:
        raise SceneError(
            f"{path}: tables or arrays nested deeper than {MAX_NESTING} levels; "
            "no scene key needs that"
        )
    return data


def named_file(base, name, limits, fail, suffixes=None):
    """The path of a file named by a scene key, checked.

    Args:
        base: the scene file's folder; ``name`` is relative to it.
        name: the key's value.
        limits: the scene's :class:`~beamfx.scene.limits.Limits`.
        fail: ``fail(message)`` raises the SceneError naming the file and key.
        suffixes: the allowed file name endings, e.g. ``(".geo", ".msh")``.
    """
    if not name or "\0" in name:
        fail(f"{name!r} is no file name")
    base = Path(base).resolve()
    path = (base / name).resolve()  # absolute names stay absolute; links are followed
    outside = not path.is_relative_to(base)
    if outside and not limits.files_outside:
        fail(
            f"{name!r} is outside the scene file's folder {base}; allowed: a file in it or "
            "below it (or set [limits] files_outside = true)"
        )
    if suffixes and path.suffix.lower() not in suffixes:
        fail(f"{name!r}: allowed: a file ending in {' or '.join(suffixes)}")
    try:
        info = os.stat(path)
    except FileNotFoundError:
        fail(f"no such file: {path}")
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    if not stat.S_ISREG(info.st_mode):
        fail(f"{path} is not a regular file (devices, FIFOs and folders are refused)")
    if info.st_size > limits.max_file_mb * 1e6:
        fail(
            f"{path} has {info.st_size / 1e6:.1f} MB; at most {limits.max_file_mb:g} MB "
            "([limits] max_file_mb)"
        )
    if not os.access(path, os.R_OK):
        fail(f"cannot read {path}: permission denied")
    return path


__all__ = ["named_file", "parse_toml", "read_toml"]
