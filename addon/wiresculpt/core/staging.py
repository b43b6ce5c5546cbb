"""A set of output files replaced together: the run writes into a hidden staging folder beside
them (inside DIR, so every move is a rename on one file system), each file is verified, and only
then are the earlier outputs moved aside and the new ones moved in, under a journal.

A kill at any moment leaves DIR with the old set or the new set, never a mix: the journal
(`.wiresculpt-journal.json`, written atomically before the first move) says which folders take
part; the next run (`recover`, called by `staged`) rolls an interrupted switch back, or finishes
one that had completed its moves, and removes stale staging and aside folders. A failure on the
way (an exception, a move that fails, a file that does not verify) leaves the earlier set exactly
as it was and no partial file behind. Files of the set are 0644, folders 0755.

The named outputs (files or whole folders) belong to the run; anything else in the folder is the
user's and is never touched.

Fault injection for the kill test (blender_tests/pure/test_staging.py): WIRESCULPT_STAGING_FAULT
= "kill:N" kills the process (SIGKILL) just before the N-th step of a switch (0-based: journal
writes, moves and removals), "slow:SECONDS" sleeps before each step.
"""
import contextlib
import json
import os
import shutil
import signal
import tempfile
import time

from .files import write_atomic

STAGING_PREFIX = ".wiresculpt-new-"
ASIDE_PREFIX = ".wiresculpt-old-"
JOURNAL = ".wiresculpt-journal.json"
FILE_MODE, DIR_MODE = 0o644, 0o755

_steps = 0


def _step():
    """Called before every step of a switch: the fault-injection point (see the module's doc)."""
    global _steps
    fault = os.environ.get("WIRESCULPT_STAGING_FAULT", "")
    if fault.startswith("slow:"):
        time.sleep(float(fault[5:]))
    elif fault.startswith("kill:") and _steps == int(fault[5:]):
        os.kill(os.getpid(), signal.SIGKILL)
    _steps += 1


def _move(source, destination, name):
    path = os.path.join(source, name)
    if not os.path.lexists(path):
        return False
    _step()
    os.replace(path, os.path.join(destination, name))
    return True


def _move_all(names, source, destination, moved):
    """Moves each existing source/name to destination/name, appending each name to `moved` as soon
    as it has moved (so a failure half-way still tells what moved)."""
    for name in names:
        if _move(source, destination, name):
            moved.append(name)


def _remove_tree(path):
    if os.path.lexists(path):
        _step()
        shutil.rmtree(path, ignore_errors=True)


def _write_journal(out_dir, journal):
    _step()
    write_atomic(os.path.join(out_dir, JOURNAL), json.dumps(journal))


def _remove_journal(out_dir):
    path = os.path.join(out_dir, JOURNAL)
    if os.path.lexists(path):
        _step()
        os.unlink(path)


# --- verification ------------------------------------------------------------------------------

def _check_blend(path):
    """A .blend written completely: Blender's header and, at the end, its ENDB block (a save cut
    short by a full disk ends anywhere; Blender then says "Missing DNA block" on opening)."""
    with open(path, "rb") as f:
        head = f.read(12)
        f.seek(max(0, os.path.getsize(path) - 32))
        tail = f.read()
    if head[:2] in (b"\x1f\x8b", b"\x28\xb5"):
        raise ValueError(f"{os.path.basename(path)} is compressed; the set is verified uncompressed")
    if not head.startswith(b"BLENDER") or b"ENDB" not in tail:
        raise ValueError(f"{os.path.basename(path)} is not a complete .blend file (truncated or damaged)")


def verify(folder, names):
    """ValueError naming the first output of `names` in `folder` that is not complete: a file of
    zero bytes, a design.json that does not read back as a design, a .blend without its header or
    its end block. Makes every file 0644 and every folder 0755 on the way."""
    for name in names:
        path = os.path.join(folder, name)
        if not os.path.lexists(path):
            continue
        paths = [path]
        if os.path.isdir(path):
            os.chmod(path, DIR_MODE)
            for root, dirs, files in os.walk(path):
                for d in dirs:
                    os.chmod(os.path.join(root, d), DIR_MODE)
                paths.extend(os.path.join(root, f) for f in files)
            paths.remove(path)
        for p in paths:
            shown = os.path.relpath(p, folder)
            if os.path.getsize(p) == 0:
                raise ValueError(f"output {shown} was written empty; the earlier outputs are kept")
            os.chmod(p, FILE_MODE)
            if p.endswith(".blend"):
                try:
                    _check_blend(p)
                except ValueError as exc:
                    raise ValueError(f"output {exc}; the earlier outputs are kept") from None
            if os.path.basename(p) == "design.json":
                try:
                    with open(p, encoding="utf-8") as f:
                        doc = json.load(f)
                    ok = isinstance(doc, dict) and doc.get("format") == "wiresculpt-design"
                except (ValueError, UnicodeDecodeError):
                    ok = False
                if not ok:
                    raise ValueError(f"output {shown} does not read back as a design; the earlier outputs are kept")


# --- the switch --------------------------------------------------------------------------------

def commit(staging, out_dir, names):
    """Replaces out_dir's `names` by staging's (an earlier output this run did not write goes too),
    under the journal. If a move fails, what was moved is put back and the error raised."""
    aside = tempfile.mkdtemp(prefix=ASIDE_PREFIX, dir=out_dir)
    journal = {"staging": os.path.basename(staging), "aside": os.path.basename(aside), "names": list(names),
               "new": [n for n in names if os.path.lexists(os.path.join(staging, n))], "state": "switching"}
    _write_journal(out_dir, journal)
    old, new = [], []
    try:
        _move_all(names, out_dir, aside, old)
        _move_all(names, staging, out_dir, new)
    except OSError:
        _move_all(new, out_dir, staging, [])
        _move_all(old, aside, out_dir, [])
        _remove_tree(aside)
        _remove_journal(out_dir)
        raise
    journal["state"] = "switched"  # the commit point: from here on the new set stays
    _write_journal(out_dir, journal)
    _remove_tree(aside)
    _remove_tree(staging)
    _remove_journal(out_dir)


def recover(out_dir):
    """Finishes or rolls back a switch a kill interrupted, then removes stale staging and aside
    folders. Returns "rolled back", "finished" or "" (nothing to do). Call before a new run."""
    if not os.path.isdir(out_dir):
        return ""
    done = ""
    path = os.path.join(out_dir, JOURNAL)
    journal = None
    if os.path.exists(path):
        try:
            with open(path, encoding="utf-8") as f:
                journal = json.load(f)
            staging = os.path.join(out_dir, os.path.basename(journal["staging"]))
            aside = os.path.join(out_dir, os.path.basename(journal["aside"]))
            names, new = list(journal["names"]), set(journal["new"])
            state = journal["state"]
        except (ValueError, KeyError, TypeError, UnicodeDecodeError):
            journal = None  # written atomically, so never half a journal; a foreign file is left
    if journal is not None:
        if state == "switched":
            done = "finished"
        else:
            # Moves ran in order: every old entry aside, then every new one in. A new entry that
            # is no longer in staging is in DIR: send it back; then every old entry comes back.
            for name in names:
                if name in new and not os.path.lexists(os.path.join(staging, name)):
                    if os.path.isdir(staging):
                        _move(out_dir, staging, name)
            for name in names:
                if os.path.isdir(aside):
                    _move(aside, out_dir, name)
            done = "rolled back"
        _remove_journal(out_dir)
    for entry in os.listdir(out_dir):
        full = os.path.join(out_dir, entry)
        if entry.startswith((STAGING_PREFIX, ASIDE_PREFIX)) and os.path.isdir(full):
            _remove_tree(full)
        elif entry.startswith("." + JOURNAL + ".") and entry.endswith(".tmp"):  # a journal write cut short
            _step()
            os.unlink(full)
    return done


@contextlib.contextmanager
def staged(out_dir, names, check=verify):
    """`with staged(DIR, names) as tmp:` write the outputs into tmp; on leaving the block without an
    exception they are verified (`check(tmp, names)`) and replace DIR's, on an exception DIR is left
    as it was. An interrupted earlier switch is finished or rolled back first."""
    os.makedirs(out_dir, exist_ok=True)
    recover(out_dir)
    staging = tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out_dir)
    try:
        yield staging
        check(staging, names)
        commit(staging, out_dir, names)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
