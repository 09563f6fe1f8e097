"""Writing output files so that none is left half-written under its final name.

A file is written to a temporary name in its destination folder and renamed into place only once
it is complete (a rename within one folder is atomic); when writing fails, the temporary file is
removed. A folder of files is built the same way, as a temporary sibling folder.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from vinculo.errors import InvalidInputError

__all__ = ["checked_file", "checked_folder", "file_written_in_place", "folder_written_in_place"]


def _permissions(path: Path, mode: int) -> None:
    """Give ``path`` the permissions a new file or folder gets (``mode`` less the umask).

    Temporary files and folders are created private (0600, 0700); the results should be as
    readable as any other file the user writes.
    """
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, mode & ~umask)


def checked_file(path: str | os.PathLike[str], suffixes: tuple[str, ...], what: str) -> Path:
    """Check an output file's path before anything is computed or written.

    Arguments:
        path: where the file will go.
        suffixes: the accepted suffixes (lower case, with the dot).
        what: what the file is (for messages), for example ``"NetCDF file"``.

    Returns:
        The path as a :class:`pathlib.Path`.

    Raises:
        InvalidInputError: the suffix is not one of ``suffixes``, the path is a folder, or its
            parent folder does not exist.
    """
    try:
        target = Path(path)
    except TypeError as exc:
        raise InvalidInputError(
            f"the {what} path must be a str or a path, got {path!r}", name="path", value=path
        ) from exc
    if target.suffix.lower() not in suffixes:
        raise InvalidInputError(
            f"unknown suffix {target.suffix!r} of the {what} {str(target)!r}: use one of "
            f"{', '.join(suffixes)}",
            name="path",
            value=str(target),
        )
    if target.is_dir():
        raise InvalidInputError(
            f"the {what} {str(target)!r} is an existing folder; give a file name",
            name="path",
            value=str(target),
        )
    if not target.parent.is_dir():
        raise InvalidInputError(
            f"the folder {str(target.parent)!r} of the {what} {str(target)!r} does not exist; "
            f"create it first",
            name="path",
            value=str(target),
        )
    return target


def checked_folder(folder: str | os.PathLike[str], what: str, overwrite: bool) -> Path:
    """Check an output folder's path before anything is written.

    Arguments:
        folder: the folder that will hold the files (created if missing).
        what: what goes in it (for messages).
        overwrite: whether a non-empty existing folder may be replaced.

    Returns:
        The folder as a :class:`pathlib.Path`.

    Raises:
        InvalidInputError: the path is an existing file, its parent folder does not exist, or it
            is a non-empty folder and ``overwrite`` is False.
    """
    try:
        target = Path(folder)
    except TypeError as exc:
        raise InvalidInputError(
            f"the {what} folder must be a str or a path, got {folder!r}",
            name="folder",
            value=folder,
        ) from exc
    if target.exists() and not target.is_dir():
        raise InvalidInputError(
            f"{str(target)!r} exists and is not a folder; give a folder for the {what}",
            name="folder",
            value=str(target),
        )
    if not target.absolute().parent.is_dir():
        raise InvalidInputError(
            f"the parent folder of {str(target)!r} does not exist; create it first",
            name="folder",
            value=str(target),
        )
    if target.is_dir() and any(target.iterdir()) and not overwrite:
        raise InvalidInputError(
            f"the folder {str(target)!r} is not empty; give a new or empty folder for the "
            f"{what}, or overwrite=True to replace it",
            name="folder",
            value=str(target),
        )
    return target


@contextlib.contextmanager
def file_written_in_place(target: Path) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; rename it to ``target`` if the block succeeds.

    The temporary name keeps ``target``'s suffix (writers that choose a format by suffix still
    work) and starts with a dot. If the block raises, the temporary file is removed and
    ``target`` is left as it was.

    Arguments:
        target: the final path (its folder must exist).

    Yields:
        The temporary path to write to.
    """
    handle, name = tempfile.mkstemp(
        dir=target.parent, prefix=f".{target.stem}.", suffix=f".part{target.suffix}"
    )
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        _permissions(temporary, 0o666)
        os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)


@contextlib.contextmanager
def folder_written_in_place(target: Path) -> Iterator[Path]:
    """Yield a temporary folder beside ``target``; move it to ``target`` if the block succeeds.

    An existing ``target`` (empty, or non-empty when the caller allowed overwriting) is replaced
    only after the new folder is complete. If the block raises, the temporary folder is removed
    and ``target`` is left as it was.

    Arguments:
        target: the final folder (its parent must exist).

    Yields:
        The temporary folder to fill.
    """
    parent = target.absolute().parent
    temporary = Path(tempfile.mkdtemp(dir=parent, prefix=f".{target.name}.", suffix=".part"))
    try:
        yield temporary
        _permissions(temporary, 0o777)
        if target.exists():
            old = Path(tempfile.mkdtemp(dir=parent, prefix=f".{target.name}.", suffix=".old"))
            os.replace(target, old / target.name)
            os.replace(temporary, target)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(temporary, target)
    finally:
        if temporary.exists():
            shutil.rmtree(temporary, ignore_errors=True)
