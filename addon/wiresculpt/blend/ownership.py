"""Results kept outside Blender data belong to one file and one scene.

The plane assistant's candidates (and their preview) live in module state, not in the scene: the
scene stays untouched until a candidate is applied. Every file's first scene is called "Scene", so a
name does not tell one file's scene from another's. An Owner says whose a result is:

- a random token, written into the scene (custom property TOKEN_PREFIX + kind) when the result is
  made: another file's scene, a scene added later, and a scene loaded from disk do not carry it;
- the scene's name: a copy of the scene (Scene > New > Full Copy) carries the token but not the name;
- the file's generation (core/session.py), advanced by the load_pre and load_post handlers here, so
  a result made before a load (or by a worker that ends after it) is never this file's.

`owns(owner, scene)` is the one check, made before anything is shown or applied. On load_pre and
load_post every callback given to `on_load` runs too (each forgets its module's state).
"""
import uuid

import bpy

from ..core import session
from .registration import handlers_factory

TOKEN_PREFIX = "wiresculpt_owner_"  # scene custom property TOKEN_PREFIX + kind: the token of that kind's result

_FORGET = []  # callbacks run on load_pre and load_post


class Owner:
    """The file generation, scene name and token a result was made for."""
    __slots__ = ("generation", "scene", "token", "kind")

    def __init__(self, generation, scene, token, kind):
        self.generation, self.scene, self.token, self.kind = generation, scene, token, kind

    def __repr__(self):
        return f"Owner(generation={self.generation}, scene={self.scene!r}, kind={self.kind!r})"


def stamp(scene, kind, generation=None):
    """A new Owner of `kind` for `scene`, its token written into the scene (replacing an earlier
    result's of that kind, which is then no longer the scene's). `generation`: the one the work
    started in (default: now); None is returned, and nothing written, when a file was loaded since."""
    now = session.generation()
    if generation is not None and generation != now:
        return None
    token = uuid.uuid4().hex
    scene[TOKEN_PREFIX + kind] = token
    return Owner(now, scene.name, token, kind)


def owns(owner, scene):
    """True when the result stamped `owner` was made for `scene` in the file now open."""
    if owner is None or scene is None:
        return False
    try:
        return (owner.generation == session.generation() and scene.name == owner.scene
                and scene.get(TOKEN_PREFIX + owner.kind) == owner.token)
    except ReferenceError:  # the scene was removed
        return False


def on_load(callback):
    """`callback()` runs on every load_pre and load_post (File > New, Open, Revert)."""
    if callback not in _FORGET:
        _FORGET.append(callback)


@bpy.app.handlers.persistent
def _loading(*_args):
    session.advance()
    for callback in list(_FORGET):
        callback()


register, _unregister = handlers_factory((("load_pre", _loading), ("load_post", _loading)))


def unregister():
    _unregister()
    _FORGET.clear()
