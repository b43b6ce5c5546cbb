"""Which file is open, as a number: the add-on keeps some state outside Blender data
(the plane assistant's candidates and preview, Live's verdict, a stream's stop), and such state
belongs to the file it was made in. `generation()` changes whenever a file is loaded or a new one
made (blend/ownership.py's load_pre and load_post handlers call `advance()`), so state stamped with
an earlier generation is from another file, even when it finishes on a worker thread after the load.

Free of bpy."""

_GENERATION = [0]


def generation():
    """The number of the file now open (it counts loads, File > New included)."""
    return _GENERATION[0]


def advance():
    """A file is being loaded or made: every earlier generation is another file's."""
    _GENERATION[0] += 1
    return _GENERATION[0]
