"""TOML scene files ↔ model descriptions. Errors name the file, the key path and what is allowed."""

from .load import Scene, SceneError, load_scene, parse_scene
from .sweep import Member, Sweep, load_scene_or_sweep, load_sweep, parse_sweep

__all__ = [
    "Member",
    "Scene",
    "SceneError",
    "Sweep",
    "load_scene",
    "load_scene_or_sweep",
    "load_sweep",
    "parse_scene",
    "parse_sweep",
]
