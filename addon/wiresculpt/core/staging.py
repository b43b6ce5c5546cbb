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

One writer per folder: `hold(DIR)` takes an exclusive lock (`flock` on `DIR/.wiresculpt-lock`,
holding the owner's process id) before recovery and keeps it to the end; `recover` and `staged`
take it themselves unless this process holds it already (the batch takes it before its solve).
A second run is refused with `FolderBusy` naming the folder and the process that holds it, so no
recovery ever removes a staging folder a live run is writing. The lock dies with its process
(a kill leaves no stale lock) and the file is removed by whoever releases it.

Fault injection for the kill test (blender_tests/pure/test_staging.py): WIRESCULPT_STAGING_FAULT
= "kill:N" kills the process (SIGKILL) just before the N-th step of a switch (0-based: journal
writes, moves and removals), "slow:SECONDS" sleeps before each step.
"""
import contextlib
import errno
import fcntl
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
LOCK = ".wiresculpt-lock"
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


# --- one writer per folder ------------------------------------------------------------------------

class FolderBusy(OSError):
    """Another process holds the folder's lock: `folder`, `pid` (None when it could not be read)."""

    def __init__(self, folder, pid):
        who = f"process {pid}" if pid else "another process"
        super().__init__(errno.EBUSY, f"--out {folder}: another wiresculpt run ({who}) is writing to this folder; "
                                      "wait for it to end or choose another --out")
        self.folder, self.pid = folder, pid

    def __str__(self):
        return self.strerror


_held = {}  # realpath of a folder -> the open lock file's descriptor, for the folders this process holds


def _holder(fd):
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
        return int(text) if text.isdigit() else None
    except OSError:
        return None


@contextlib.contextmanager
def hold(out_dir, shown=None):
    """`with hold(DIR):` this process is the folder's one writer until the block ends; FolderBusy
    (naming `shown`, default DIR) when another process is. DIR must exist. Re-entrant within a
    process."""
    key = os.path.realpath(out_dir)
    if key in _held:
        yield
        return
    path = os.path.join(out_dir, LOCK)
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, FILE_MODE)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            pid = _holder(fd)
            os.close(fd)
            raise FolderBusy(shown or out_dir, pid) from None
        except BaseException:
            os.close(fd)
            raise
        try:  # the holder before us may have removed the file as it let go: lock the one at `path`
            same = os.fstat(fd).st_ino == os.stat(path, follow_symlinks=False).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        _held[key] = fd
        yield
    finally:
        _held.pop(key, None)
        with contextlib.suppress(OSError):
            os.unlink(path)  # still held: a process waiting on this file finds it gone and starts again
        os.close(fd)


@contextlib.contextmanager
def claim(out_dir):
    """`with claim(DIR):` DIR created when missing (with its missing parents) and held (`hold`)
    until the block ends; folders it created are removed again when they are left empty (a refused
    run leaves nothing behind). ValueError naming --out when DIR cannot be created or written,
    FolderBusy when another run holds it."""
    path = os.path.abspath(out_dir)
    created, probe = [], path
    while not os.path.lexists(probe):
        created.append(probe)
        probe = os.path.dirname(probe)
    entered = False
    try:
        try:
            os.makedirs(path, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"--out {out_dir}: the folder cannot be created ({exc.strerror})") from None
        with hold(path, out_dir):
            entered = True
            yield path
    except OSError as exc:
        if entered or isinstance(exc, FolderBusy):
            raise
        raise ValueError(f"--out {out_dir}: cannot write in the folder ({exc.strerror})") from None
    finally:
        for folder in created:  # deepest first
            with contextlib.suppress(OSError):
                os.rmdir(folder)


def check_kinds(out_dir, files=(), folders=(), shown=None):
    """ValueError naming the path when an entry of DIR is a folder where the run writes a file
    (`files`) or a file where it writes a folder (`folders`): replacing it would delete the user's
    files."""
    shown = shown or out_dir
    for name in files:
        if os.path.isdir(os.path.join(out_dir, name)):
            raise ValueError(f"--out {shown}: {os.path.join(shown, name)} is a folder, where the run writes the file "
                             f"{name}; move it away or choose another --out")
    for name in folders:
        full = os.path.join(out_dir, name)
        if os.path.lexists(full) and not os.path.isdir(full):
            raise ValueError(f"--out {shown}: {os.path.join(shown, name)} is a file, where the run writes the folder "
                             f"{name}/; move it away or choose another --out")


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
    under the journal. If a move fails, what was moved is put back and the error raised. An entry of
    DIR that is a folder where the new set has a file, or a file where it has a folder, is not
    replaced: ValueError naming it, DIR as it was."""
    new_kinds = {n: os.path.isdir(os.path.join(staging, n)) for n in names if os.path.lexists(os.path.join(staging, n))}
    check_kinds(out_dir, [n for n, d in new_kinds.items() if not d], [n for n, d in new_kinds.items() if d])
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
    with hold(out_dir):
        return _recover(out_dir)


def _recover(out_dir):
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
    as it was. An interrupted earlier switch is finished or rolled back first. The folder's lock
    (`hold`) is held throughout: FolderBusy when another process writes DIR."""
    os.makedirs(out_dir, exist_ok=True)
    with hold(out_dir):
        recover(out_dir)
        staging = tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out_dir)
        try:
            yield staging
            check(staging, names)
            commit(staging, out_dir, names)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
