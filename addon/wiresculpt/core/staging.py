"""A set of output files replaced together: the run writes into a hidden folder beside them and
only when everything is written are the earlier outputs moved aside and the new ones moved in.
A failure on the way leaves the earlier set exactly as it was and no partial file behind.

The named outputs (files or whole folders) belong to the run; anything else in the folder is the
user's and is never touched.
"""
import contextlib
import os
import shutil
import tempfile

STAGING_PREFIX = ".wiresculpt-new-"
ASIDE_PREFIX = ".wiresculpt-old-"


def _move_all(names, source, destination, moved):
    """Moves each existing source/name to destination/name, appending each name to `moved` as soon
    as it has moved (so a failure half-way still tells what moved)."""
    for name in names:
        path = os.path.join(source, name)
        if os.path.lexists(path):
            os.replace(path, os.path.join(destination, name))
            moved.append(name)


def commit(staging, out_dir, names):
    """Replaces out_dir's `names` by staging's (an earlier output this run did not write goes too).
    If a move fails, what was moved is put back and the error raised."""
    aside = tempfile.mkdtemp(prefix=ASIDE_PREFIX, dir=out_dir)
    old, new = [], []
    try:
        _move_all(names, out_dir, aside, old)
        _move_all(names, staging, out_dir, new)
    except OSError:
        _move_all(new, out_dir, staging, [])
        _move_all(old, aside, out_dir, [])
        shutil.rmtree(aside, ignore_errors=True)
        raise
    shutil.rmtree(aside, ignore_errors=True)


@contextlib.contextmanager
def staged(out_dir, names):
    """`with staged(DIR, names) as tmp:` write the outputs into tmp; on leaving the block without an
    exception they replace DIR's, on an exception DIR is left as it was."""
    os.makedirs(out_dir, exist_ok=True)
    staging = tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out_dir)
    try:
        yield staging
        commit(staging, out_dir, names)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
