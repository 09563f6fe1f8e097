"""Reading a small numeric CSV table with named columns, for the user's measurement files.

The format shared by the files of :mod:`vinculo.buoy.data` and :mod:`vinculo.buoy.tank`: one row
of comma-separated numbers per sample; an optional header row naming the columns (any order, any
letter case, a unit in parentheses or brackets allowed, as in ``time (s)``; other columns are
ignored); without a header the required columns come in their stated order. Anything after ``#``
on a line is a comment, and blank lines are skipped. Every error names the file and, where there
is one, the line (1-based), and quotes it.

Plain numeric rows are parsed by :func:`numpy.loadtxt` (a record of 10^6 samples reads in about
a second); anything else (quoted fields, empty optional fields, a malformed row) goes through a
line-by-line reader that also finds and names the first bad line.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = ["Table", "read_table", "table_error"]

_UNIT = re.compile(r"\s*[\(\[].*[\)\]]\s*$")


@dataclass(frozen=True)
class Table:
    """The numbers of a CSV table.

    Attributes:
        values: one row per data line, one column per required column, shape (n, k).
        lines: the 1-based line number of each row, shape (n,).
        source: every line of the file, for messages that quote one.
        path: the file read.
        name: the ``name`` given to errors about it.
    """

    values: np.ndarray
    lines: np.ndarray
    source: list[str]
    path: Path
    name: str = "data"

    def error(self, row: int, message: str) -> InvalidInputError:
        """An error about data row ``row`` (0-based), naming its line and quoting it."""
        line = int(self.lines[row])
        return table_error(
            f"{message}: {self.source[line - 1].strip()!r}", self.path, line, self.name
        )


def table_error(
    message: str, path: Path, line: int | None, name: str = "data"
) -> InvalidInputError:
    """An error about a data file, naming it (and the line, when there is one)."""
    where = f"{path}, line {line}" if line is not None else str(path)
    return InvalidInputError(f"{where}: {message}", name=name, path=str(path), line=line)


def _column_name(field: str) -> str:
    """A header field without its unit and case: ``"Frequency (Hz)"`` -> ``"frequency"``."""
    return _UNIT.sub("", field).strip().lower()


def _is_number(field: str) -> bool:
    """Whether a field parses as a float (NaN and infinity included: they are numbers here)."""
    try:
        float(field)
    except ValueError:
        return False
    return True


def read_table(
    path: str | Path,
    columns: tuple[str, ...],
    *,
    what: str,
    name: str = "data",
    optional: tuple[str, ...] = (),
) -> Table:
    """Read the required ``columns`` of a CSV file (format in the module docstring).

    Arguments:
        path: the CSV file.
        columns: the required column names, in their order for a file without a header.
        optional: columns read when a header names them (NaN otherwise, and in empty fields);
            they follow the required ones in :attr:`Table.values`.
        what: what the file is, for messages (``"measurement file"``).
        name: the ``name`` of the errors raised (the option or argument that gave the file).

    Returns:
        The :class:`Table` (finite numbers only).

    Raises:
        InvalidInputError: (with ``path`` and ``line``) if the file is missing or unreadable, a
            header lacks a required column, a row has the wrong number of fields or a value that
            is not a finite number, or there is no data row.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise table_error(f"no such {what}; check the path", path, None, name) from None
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise table_error(f"cannot read the {what}: {reason}", path, None, name) from None

    source = text.splitlines()
    contents = [line.split("#", 1)[0] for line in source] if "#" in text else source
    data_lines = [k for k, content in enumerate(contents) if content.strip()]
    indices: dict[str, int] | None = None
    width = len(columns)
    if data_lines:
        first = data_lines[0]
        fields = [field.strip() for field in next(csv.reader([contents[first]]))]
        if not all(_is_number(field) for field in fields):
            names = [_column_name(field) for field in fields]
            missing = [c for c in columns if c not in names]
            raw = source[first]
            if missing and any(_is_number(field) for field in fields):
                bad = next(field for field in fields if not _is_number(field))
                raise table_error(
                    f"{bad!r} is not a number, and the line is no header (it lacks the "
                    f"column(s) {', '.join(missing)}): {raw.strip()!r}",
                    path, first + 1, name,
                )
            if missing:
                raise table_error(
                    f"the header {raw.strip()!r} lacks the column(s) {', '.join(missing)}; name "
                    f"the columns {', '.join(columns)} (any order), or drop the header and give "
                    f"the {len(columns)} columns in that order",
                    path, first + 1, name,
                )
            indices = {c: names.index(c) for c in (*columns, *optional) if c in names}
            width = len(fields)
            data_lines = data_lines[1:]
    order = indices or {c: k for k, c in enumerate(columns)}
    if not data_lines:
        raise table_error(
            f"no data rows (only blank lines, comments or a header); add rows of "
            f"{', '.join(columns)}",
            path, None, name,
        )
    rows = [contents[k] for k in data_lines]
    values = _parse_fast(rows, width, order, columns, optional)
    if values is None:
        values = _parse_slow(rows, data_lines, source, width, order, columns, optional, path,
                             name)
    return Table(values, np.array(data_lines, dtype=np.int64) + 1, source, path, name)


def _parse_fast(
    rows: list[str],
    width: int,
    order: dict[str, int],
    columns: tuple[str, ...],
    optional: tuple[str, ...],
) -> np.ndarray | None:
    """The rows parsed by numpy, or None when they need the line-by-line reader (quotes, a
    row of another width, an empty or non-numeric field, a value that is not finite)."""
    if any('"' in row for row in rows):
        return None
    commas = np.fromiter((row.count(",") for row in rows), dtype=np.int64, count=len(rows))
    if np.any(commas != width - 1):
        return None
    wanted = [c for c in (*columns, *optional) if c in order]
    try:
        parsed = np.loadtxt(
            rows, delimiter=",", usecols=[order[c] for c in wanted], dtype=np.float64,
            comments=None, ndmin=2,
        )
    except ValueError:
        return None
    if not np.all(np.isfinite(parsed)):
        return None
    values = np.full((len(rows), len(columns) + len(optional)), np.nan)
    for k, column in enumerate((*columns, *optional)):
        if column in order:
            values[:, k] = parsed[:, wanted.index(column)]
    return values


def _parse_slow(
    rows: list[str],
    data_lines: list[int],
    source: list[str],
    width: int,
    order: dict[str, int],
    columns: tuple[str, ...],
    optional: tuple[str, ...],
    path: Path,
    name: str,
) -> np.ndarray:
    """The rows parsed one by one (csv quoting, empty optional fields), raising at the first
    bad one with its line."""
    values: list[list[float]] = []
    for content, k in zip(rows, data_lines, strict=True):
        number, raw = k + 1, source[k]
        fields = [field.strip() for field in next(csv.reader([content]))]
        if len(fields) != width:
            raise table_error(
                f"expected {width} comma-separated fields, found {len(fields)}: {raw.strip()!r}",
                path, number, name,
            )
        row = []
        for column in (*columns, *optional):
            if column not in order or (column in optional and not fields[order[column]]):
                row.append(math.nan)
                continue
            field = fields[order[column]]
            try:
                value = float(field)
            except ValueError:
                raise table_error(
                    f"{column} {field!r} is not a number: {raw.strip()!r}", path, number, name
                ) from None
            if not math.isfinite(value):
                raise table_error(
                    f"{column} {field!r} is not a finite number: {raw.strip()!r}",
                    path, number, name,
                )
            row.append(value)
        values.append(row)
    return np.array(values, dtype=np.float64).reshape(len(rows), len(columns) + len(optional))
