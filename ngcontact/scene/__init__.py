"""Scenes: TOML files validated into frozen descriptions (no model objects).

The only layer that raises :class:`ngcontact.errors.SceneError`; the explicit
table of kinds is :data:`ngcontact.scene.kinds.KINDS`.
"""
