"""Atomic file writing: a result is either the old file or the complete new one, never a part."""
import os
import tempfile


def write_atomic(path, data):
    """Writes `data` (str or bytes) to `path` through a temporary file in the same folder and a
    rename, creating the folder if needed."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    mode = "wb" if isinstance(data, (bytes, bytearray)) else "w"
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    try:
        # the file object owns the descriptor at once: closed on any error before the unlink below,
        # which Windows refuses while it is open (a sharing violation)
        with os.fdopen(fd, mode, **({} if mode == "wb" else {"encoding": "utf-8", "newline": "\n"})) as f:
            if hasattr(os, "fchmod"):  # not on Windows before Python 3.13, whose files have no such bits
                os.fchmod(f.fileno(), 0o644)  # mkstemp makes 0600: results are for others to read too
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
