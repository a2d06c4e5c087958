"""Checked file paths and atomic writes, shared by every writer in the package.

Reading: :func:`check_input` turns the usual surprises (no such file, a folder, no permission)
into one clear ``OSError`` naming the file and what was expected.

Writing: :func:`check_output` refuses a folder, an existing file without ``overwrite``, a
missing or unwritable folder — before any work is done. :func:`atomic_write` then writes to a
temporary file beside the destination and renames it over the destination in one step, so a
reader never sees a half-written file.

Temporary files are named ``.<name>.<pid>.<random>.motionlab-tmp``. A write that is killed
(``kill -9``, power loss) cannot remove its own; the next write to the same destination removes
every such file whose process no longer runs (:func:`remove_stale`), so they never pile up and
a running writer's file is never touched.
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = [
    "TMP_SUFFIX",
    "check_input",
    "bvh_files",
    "check_output",
    "check_replaceable",
    "exists_message",
    "atomic_write",
    "atomic_write_all",
    "atomic_write_file",
    "remove_stale",
    "remove_stale_in",
]

TMP_SUFFIX = ".motionlab-tmp"
"""Ending of every temporary file a motionlab writer creates."""


def bvh_files(folder: str | os.PathLike, recursive: bool = False) -> list[Path]:
    """The files in ``folder`` (and its subfolders when ``recursive``) whose suffix is ``.bvh`` in
    any case, sorted."""
    found = Path(folder).rglob("*") if recursive else Path(folder).glob("*")
    return sorted(p for p in found if p.suffix.lower() == ".bvh" and p.is_file())


def check_input(path: str | os.PathLike, what: str = "input") -> Path:
    """``path`` as a Path after checking it is a readable file.

    Raises
    ------
    FileNotFoundError, IsADirectoryError, PermissionError
        With a message naming ``what`` and the path.
    OSError
        ``path`` is a named pipe, a device or a socket (a link to a file is read).
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"{what} {path} is a folder; expected a file")
    if not path.exists():
        raise FileNotFoundError(f"{what} file {path} not found")
    kind = _kind(path.resolve())
    if kind is not None:  # reading a named pipe or a device can wait forever, or never end
        raise OSError(f"{what} {path} is {kind}, not a file; expected a file")
    if not os.access(path, os.R_OK):
        raise PermissionError(f"{what} file {path} is not readable (permission denied)")
    return path


def _kind(path: Path) -> str | None:
    """What ``path`` is when it is not a plain file or folder to write (a link, a named pipe, ...)."""
    if path.is_symlink():
        return f"a symbolic link (to {os.readlink(path)})"
    try:
        mode = path.stat().st_mode
    except OSError:
        return None
    for test, name in ((stat.S_ISFIFO, "a named pipe"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):  # fmt: skip
        if test(mode):
            return name
    return None


def check_replaceable(path: str | os.PathLike, what: str = "output") -> None:
    """Refuse, even with ``overwrite``, a destination that a write would not replace as a file:
    a symbolic link (the write would replace the link, not what it points to), a named pipe, a
    device or a socket, or a name ending in a path separator (a folder's name).

    Raises
    ------
    FileExistsError
        saying what ``path`` is.
    IsADirectoryError
        ``path`` ends in a separator (``newdir/``).
    """
    text = os.fspath(path)
    if text.endswith(("/", os.sep)):
        raise IsADirectoryError(f"{what} {text} ends in {text[-1]!r}, so it names a folder; expected a file name")
    kind = _kind(Path(path))
    if kind is not None:
        raise FileExistsError(
            f"{what} {text} is {kind}, not a file; motionlab replaces only plain files, --force or not"
        )


def exists_message(what: str, path) -> str:
    """The one wording of the refusal to replace an existing file."""
    return f"{what} {path} exists; add --force to replace it (overwrite=True in Python), or choose another name"


def check_output(path: str | os.PathLike, overwrite: bool = False, what: str = "output") -> Path:
    """``path`` as a Path after checking that a file can be written there.

    Raises
    ------
    IsADirectoryError
        ``path`` is a folder, or ends in a path separator.
    FileExistsError
        ``path`` exists and ``overwrite`` is False, or is a link, named pipe, device or socket
        (:func:`check_replaceable`).
    FileNotFoundError
        The folder ``path`` would go in does not exist.
    PermissionError
        That folder is not writable.
    """
    check_replaceable(path, what)
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"{what} {path} is a folder; expected a file name")
    if path.exists() and not overwrite:
        raise FileExistsError(exists_message(what, path))
    folder = path.parent
    if not folder.is_dir():
        raise FileNotFoundError(f"folder {folder} for the {what} {path.name} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PermissionError(f"cannot write the {what} {path.name} into {folder} (permission denied)")
    return path


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale(path: str | os.PathLike) -> list[Path]:
    """Remove temporary files left beside ``path`` by writers that no longer run; returns them."""
    path = Path(path)
    name = re.escape(path.name)
    return _remove_stale(path.parent, rf"\.{name}\.(\d+)\.[^.]+{re.escape(TMP_SUFFIX)}(?:{re.escape(path.suffix)})?\Z")


def remove_stale_in(folder: str | os.PathLike) -> list[Path]:
    """Remove every temporary file in ``folder`` left by a motionlab writer that no longer runs."""
    return _remove_stale(Path(folder), rf"\..+\.(\d+)\.[^.]+{re.escape(TMP_SUFFIX)}(?:\.[^.]+)?\Z")


def _remove_stale(folder: Path, regex: str) -> list[Path]:
    pattern = re.compile(regex)
    removed = []
    try:
        entries = list(folder.iterdir())
    except OSError:
        return removed
    for entry in entries:
        m = pattern.match(entry.name)
        if m and int(m.group(1)) != os.getpid() and not _alive(int(m.group(1))):
            try:
                entry.unlink()
                removed.append(entry)
            except OSError:
                pass
    return removed


def atomic_write_all(outputs: list[tuple], overwrite: bool = False) -> list[Path]:
    """Write several files as one: every temporary file is complete before the first rename.

    ``outputs`` holds ``(path, write, binary, what)`` tuples as for :func:`atomic_write`. If
    any ``write`` fails, no destination is touched; the renames at the end, in the order of
    ``outputs``, cannot fail short of a system failure.
    """
    checked = [(check_output(path, overwrite, what), write, binary, what) for path, write, binary, what in outputs]
    temps: list[str] = []
    with _removed_on_error(temps):
        for path, write, binary, what in checked:
            remove_stale(path)
            temps.append(_write_temporary(path, write, binary, what))
        for tmp, (path, *_) in zip(temps, checked, strict=True):
            os.replace(tmp, path)
    return [path for path, *_ in checked]


@contextlib.contextmanager
def _removed_on_error(temps: list[str]):
    """On any error (also ``KeyboardInterrupt``) inside the block, remove the files in ``temps`` and re-raise."""
    try:
        yield
    except BaseException:
        for tmp in temps:
            if os.path.exists(tmp):
                os.unlink(tmp)
        raise


def _umask() -> int:
    """The process umask, read without changing it where Linux shows it (``/proc/self/status``)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    umask = os.umask(0o022)  # elsewhere: read by setting, then set back at once
    os.umask(umask)
    return umask


def _mode(path: Path) -> int:
    """Permissions for ``path``'s new contents: the old file's, or what ``open`` gives a new file."""
    return path.stat().st_mode & 0o777 if path.exists() else 0o666 & ~_umask()


def _write_temporary(path: Path, write: Callable, binary: bool, what: str, by_name: bool = False) -> str:
    """A complete temporary file beside ``path`` holding what ``write(f)`` wrote (``by_name``:
    ``write(tmp_path)``, ``tmp_path`` ending in ``path``'s suffix), with ``path``'s mode, on disk."""
    mode = _mode(path)
    suffix = TMP_SUFFIX + (path.suffix if by_name else "")
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.{os.getpid()}.", suffix=suffix)
    except OSError as e:  # the folder refuses new files: say which output, not the temporary name
        raise type(e)(f"cannot write the {what} {path}: {(e.strerror or str(e)).lower()}") from None
    with _removed_on_error([tmp]):
        if by_name:
            os.close(fd)
            write(Path(tmp))
        else:
            with os.fdopen(
                fd, "wb" if binary else "w", **({} if binary else {"encoding": "utf-8", "newline": "\n"})
            ) as f:
                write(f)
                f.flush()
                os.fsync(f.fileno())
        os.chmod(tmp, mode)
    return tmp


def atomic_write(
    path: str | os.PathLike, write: Callable, overwrite: bool = False, binary: bool = False, what: str = "output"
) -> Path:
    """Write a file in one step: ``write(f)`` fills a temporary file that then replaces ``path``.

    Parameters
    ----------
    path : str or PathLike      the destination
    write : callable            ``write(f)`` with ``f`` an open file (text, UTF-8, ``\\n`` line ends,
                                or binary when ``binary``)
    overwrite : bool            replace an existing ``path`` (default: refuse)
    what : str                  what messages call the file

    The new file gets the old file's permissions, or the umask's for a new one. On any error
    (also ``KeyboardInterrupt``) the temporary file is removed and ``path`` is unchanged.
    """
    path = check_output(path, overwrite, what)
    remove_stale(path)
    tmp = _write_temporary(path, write, binary, what)
    with _removed_on_error([tmp]):
        os.replace(tmp, path)
    return path


def atomic_write_file(
    path: str | os.PathLike, fill: Callable[[Path], None], overwrite: bool = False, what: str = "output"
) -> Path:
    """:func:`atomic_write` for writers that need a file name (a movie encoder, an image library):
    ``fill(tmp)`` writes the temporary file ``tmp``, a Path beside ``path`` ending in its suffix.

    Raises
    ------
    OSError
        as :func:`check_output` says for ``path``; whatever ``fill`` raises (``path`` unchanged).
    """
    path = check_output(path, overwrite, what)
    remove_stale(path)
    tmp = _write_temporary(path, fill, True, what, by_name=True)
    with _removed_on_error([tmp]):
        os.replace(tmp, path)
    return path
