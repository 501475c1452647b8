"""TOML scene files ↔ model descriptions. Errors name the file, the key path and what is allowed."""

from .load import Scene, SceneError, load_scene, parse_scene

__all__ = ["Scene", "SceneError", "load_scene", "parse_scene"]
