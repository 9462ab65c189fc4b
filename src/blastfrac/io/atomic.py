"""Atomic file writes: write to a temporary name in the same directory, then ``os.replace``.

A run killed mid-write (``kill -9``, out of memory, an exception) then leaves either the previous
file or the new one, never a truncated or empty file. The temporary file is ``.NAME.XXXX.tmp``
next to the target and is removed when the write fails.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _temp_name(path: Path) -> Path:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())     # mkstemp creates 0600; give the file the usual permissions
    return Path(tmp)


def write_atomic(path: str | Path, writer: Callable[[Path], None]) -> None:
    """Call ``writer(tmp_path)`` to write the file, then move it onto ``path`` in one step.

    If ``writer`` raises, the temporary file is removed, ``path`` is left as it was and the
    exception propagates.
    """
    path = Path(path)
    tmp = _temp_name(path)
    try:
        writer(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextmanager
def atomic_open(path: str | Path, mode: str = "w", **kwargs) -> Iterator:
    """``open`` for writing whose result appears at ``path`` only when the block completes."""
    if not any(c in mode for c in "wx") or "+" in mode:
        raise ValueError(f"atomic_open is for writing a whole file (mode 'w' or 'wb'), not {mode!r}")
    path = Path(path)
    tmp = _temp_name(path)
    try:
        with open(tmp, mode.replace("x", "w"), **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """``Path.write_text``, atomically."""
    with atomic_open(path, "w", encoding=encoding) as fh:
        fh.write(text)
