"""Reading MoorDyn's small numeric files (seafloor grids, current profiles, wave components,
stiffness curves): the file's lines, and a row's numbers, with errors that name the file, the
line and the field (:class:`vinculo.errors.MooringFileError`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from vinculo.errors import MooringFileError

__all__ = ["file_error", "numbers", "read_lines", "write_lines"]


def file_error(name: str, line: int | None, field: str | None, message: str,
               value: object = None) -> MooringFileError:
    """The error ``"<file>, line <n>: <field>: <message>"`` (the parts that are known)."""
    where = f"{name}, line {line}" if line is not None else name
    head = f"{where}: {field}: " if field else f"{where}: "
    return MooringFileError(head + message, file=name, line=line, field=field, value=value)


def read_lines(path: str | Path, what: str) -> list[str]:
    """The lines of the file ``path`` (``what`` it is, for the error).

    Raises:
        MooringFileError: when the file cannot be read.
    """
    try:
        return Path(path).read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise MooringFileError(f"cannot read the {what} {str(path)!r}: {exc.strerror}",
                               file=str(path), line=None, field=None, value=None) from None


def numbers(name: str, line: int, fields: Sequence[str], names: Sequence[str]) -> list[float]:
    """The finite numbers of a row's ``fields``: the k-th is the field ``names[k]``, or, with
    one name for the whole row, that name's entry k + 1 (``"x tick 3"``).

    Raises:
        MooringFileError: for a field that is not a finite number, naming it.
    """
    values = []
    for k, text in enumerate(fields):
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            if len(names) == 1:
                field, label = names[0], f"{names[0]} {k + 1}"
            else:
                field = label = names[min(k, len(names) - 1)]
            raise MooringFileError(f"{name}, line {line}: {label}: {text!r} is not a finite "
                                   f"number", file=name, line=line, field=field, value=text)
        values.append(value)
    return values


def write_lines(path: str | Path, rows: Sequence[str], *, final_newline: bool = True) -> Path:
    """Write ``rows`` as the lines of the file ``path`` (replaced if it exists), with a newline
    after the last unless ``final_newline`` is False (MoorDyn 2.7 reads an empty last line of a
    curve file as a point).

    Returns:
        The path written.
    """
    path = Path(path)
    path.write_text("\n".join(rows) + ("\n" if final_newline else ""), encoding="utf-8")
    return path
