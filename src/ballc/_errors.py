"""The error a scene's bad value raises (ballc.SceneError), here so that both
ballc.scene and ballc.planes raise it without importing each other."""


class SceneError(ValueError):
    """A scene parameter has a value ballc cannot simulate."""
