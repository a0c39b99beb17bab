"""Writing files so that a failed run never leaves a half-written or clobbered file behind."""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
from pathlib import Path

from pianobot.errors import PianobotError, quote

_REASONS = {
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "read-only file system",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "file too large for the file system",
    errno.ELOOP: "a loop of symbolic links",
    errno.ENAMETOOLONG: "file name too long",
}


def why(error: OSError) -> str:
    """An OSError's reason in a few words, on one line ('no space left on the device')."""
    if error.errno in _REASONS:
        return _REASONS[error.errno]
    text = error.strerror or str(error) or type(error).__name__
    return quote(text.strip().splitlines()[0] if text.strip() else type(error).__name__, 80)


def _fix(error: OSError) -> str:
    if error.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
        return "free some space or choose another folder"
    return "choose another folder"


def _prefix(path: Path) -> str:
    """A temporary file's name prefix: short enough that a long file name still leaves room."""
    return f".{path.name[:64]}."


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def check_writable(path: str | os.PathLike) -> Path:
    """Fail early, before any work is done, if ``path`` cannot be written.

    The folder is really tried: a small temporary file is created there, written and removed,
    so a read-only, full or forbidden folder is reported now rather than after the work.
    """
    path = Path(path)
    if path.is_dir():
        raise PianobotError(f"{path} is a folder: give a file name to write to")
    if not path.parent.is_dir():
        raise PianobotError(f"folder {path.parent} does not exist: create it first or choose another path")
    if path.exists() and not path.is_file():
        raise PianobotError(f"{path} is not a regular file (a device, FIFO or socket): choose another file name")
    try:
        fd, probe = tempfile.mkstemp(prefix=_prefix(path), suffix=".tmp", dir=path.parent)
        try:
            os.write(fd, b"pianobot")
        finally:
            os.close(fd)
            os.unlink(probe)
    except OSError as e:
        raise PianobotError(f"cannot write {path} in folder {path.parent} ({why(e)}): {_fix(e)}") from None
    return path


def not_written(path: Path, error: OSError) -> PianobotError:
    """The one-line error for a write that failed part-way (the temporary file is already gone)."""
    kept = "the existing file is unchanged" if path.exists() else "nothing was written"
    return PianobotError(f"could not write {path} ({why(error)}): {kept}; {_fix(error)}")


def atomic_write(path: str | os.PathLike, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` via a temporary file in the same folder and an atomic rename.

    Either the whole new file is there afterwards, or the old one (if any) is untouched.
    An OSError on the way (a full disk) becomes a one-line :class:`PianobotError` naming the file.
    """
    path = check_writable(path)
    payload = data.encode() if isinstance(data, str) else data
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=_prefix(path), suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as f:
            f.write(payload)
            f.flush()
            os.fsync(f.fileno())
        move_into_place(tmp, path)
    except BaseException as e:
        if tmp is not None:
            with contextlib.suppress(OSError):
                Path(tmp).unlink(missing_ok=True)
        if isinstance(e, OSError):
            raise not_written(path, e) from None
        raise
    return path


def temporary_beside(path: Path) -> str:
    """A new temporary file name in ``path``'s folder (same file system: the rename is atomic)."""
    fd, tmp = tempfile.mkstemp(prefix=_prefix(path), suffix=".tmp" + path.suffix, dir=path.parent)
    os.close(fd)
    return tmp


def move_into_place(tmp: str | os.PathLike, path: str | os.PathLike) -> None:
    """Give a finished temporary file the usual permissions (mkstemp makes 0600) and rename it over ``path``."""
    os.chmod(tmp, 0o666 & ~_umask())
    os.replace(tmp, path)


def read_input(path: str | os.PathLike, *, limit: int, kind: str, missing: str | None = None) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them, or a one-line error.

    Refuses folders, devices, FIFOs and sockets (whose ``st_size`` says nothing: /dev/zero never
    ends, a FIFO may never answer) and symbolic-link loops, and never reads more than ``limit``
    bytes, whatever the file claims. ``kind`` names what was expected ('.mid file'); ``missing``
    replaces the message for a file that does not exist.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            raise PianobotError(f"{path} is a symbolic link to a file that does not exist: give a {kind}") from None
        raise PianobotError(missing or f"no such file: {path}") from None
    except OSError as e:
        if e.errno == errno.ELOOP:
            raise PianobotError(f"{path} is a loop of symbolic links: give the {kind} itself") from None
        raise PianobotError(f"cannot read {path} ({why(e)}): give a readable {kind}") from None
    if stat.S_ISDIR(info.st_mode):
        raise PianobotError(f"{path} is a folder: give a {kind}")
    too_large = PianobotError(f"{path} is larger than {limit / 1e6:g} MB: that is not a piano piece; give a {kind}")
    if not stat.S_ISREG(info.st_mode):
        raise PianobotError(f"{path} is not a regular file (a device, FIFO or socket): give a {kind}")
    if info.st_size > limit:
        raise too_large
    try:
        # O_NONBLOCK: a FIFO put there since the stat must not hang the open
        with os.fdopen(os.open(path, os.O_RDONLY | os.O_NONBLOCK), "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise PianobotError(f"{path} is not a regular file (a device, FIFO or socket): give a {kind}")
            data = f.read(limit + 1)
    except OSError as e:
        raise PianobotError(f"cannot read {path} ({why(e)}): give a readable {kind}") from None
    if len(data) > limit:
        raise too_large
    return data


_KINDS = (
    (lambda data: data.startswith(b"MThd"), "a MIDI file", (".mid", ".midi")),
    (lambda data: data.startswith(b"PK\x03\x04"), "a zip file, as a compressed MusicXML score is", (".mxl",)),
    (lambda data: data.startswith(b"<") and b"<score-" in data[:65536], "a MusicXML score", (".musicxml", ".xml")),
)
"""What a file's first bytes say it is (after a byte order mark), and the names that kind of file has."""


def content_kind(data: bytes) -> tuple[str, tuple[str, ...]] | None:
    """What kind of file pianobot reads ``data`` is, by its first bytes, and that kind's suffixes; None for none."""
    data = data.removeprefix(b"\xef\xbb\xbf")
    return next(((kind, suffixes) for test, kind, suffixes in _KINDS if test(data)), None)


def renamed(path: Path, suffixes: tuple[str, ...]) -> str:
    """``path``'s name with the first of ``suffixes`` ('song.mid.xml' -> 'song.mid', 'song.xml' -> 'song.mid')."""
    stem = Path(path.stem)
    return stem.name if stem.suffix.lower() in suffixes else f"{stem.name}{suffixes[0]}"


def misnamed(path: Path, data: bytes) -> str:
    """Where ``data``, read from ``path``, is a kind of file pianobot reads that ``path``'s suffix
    does not name, the one line that says so and how to name it; else ''."""
    found = content_kind(data)
    if found is None or path.suffix.lower() in found[1]:
        return ""
    named = f"its name's {path.suffix}" if path.suffix else "its name, without a suffix,"
    return f"{path} holds {found[0]}, not what {named} says: name it {renamed(path, found[1])}"
