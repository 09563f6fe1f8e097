"""MoorDyn's output channels (the OUTPUTS section): the quantities a run writes, by name.

Supported (MoorDyn's names, any case; ``n`` a line or point number, ``m`` a node number along a
line from 0 at end A to N at end B):

- ``FAIRTEN<n>`` and ``ANCHTEN<n>`` (also ``LINE<n>TENB`` and ``LINE<n>TENA``): the tension at
  line n's end B and end A, the magnitude of the line's force on its end point (N);
- ``L<n>N<m>P{X,Y,Z}`` / ``LINE<n>N<m>P{X,Y,Z}``: a node's position (m); ``V{X,Y,Z}``: its
  velocity (m/s); ``T`` or ``TEN``: its tension (N), the mean of its two segments' tensions
  for an inner node and the end tension for an end node (MoorDyn's rule);
- ``CON<n>`` / ``POINT<n>`` with ``P{X,Y,Z}`` or ``V{X,Y,Z}``: a point's position or velocity;
  with ``F{X,Y,Z}``, for a fixed or coupled point, the load it takes (N): the forces of its
  lines on it with its own weight and buoyancy (MoorDyn's net force of such a point: an
  anchor's load, a fairlead's). A free point's net force (its mass times its acceleration, with
  its drag) is not given.

A run of a file with OUTPUTS writes them beside its other results (``channels.csv``: ``time``
and one column per channel, named as in the file); :func:`parse_channel` refuses a name it does
not know, naming it and the supported forms.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = ["Channel", "channel_values", "parse_channel"]

_LINE_END = re.compile(r"(FAIRTEN|ANCHTEN)(\d+)|LINE(\d+)TEN([AB])")
_NODE = re.compile(r"(?:L|LINE)(\d+)N(\d+)(PX|PY|PZ|VX|VY|VZ|TEN|T)")
_POINT = re.compile(r"(?:CON|POINT)(\d+)(PX|PY|PZ|VX|VY|VZ|FX|FY|FZ)")


@dataclass(frozen=True)
class Channel:
    """One output channel.

    Arguments:
        name: its name, as written in the file.
        kind: ``"end"`` (a line's end tension), ``"node"`` or ``"point"``.
        number: the line's or the point's number (1-based).
        node: the node (``"end"``: 0 for end A, 1 for end B; ``"node"``: its index).
        quantity: ``"tension"``, or ``"p"``/``"v"`` with the axis (``"px"``, ...).
    """

    name: str
    kind: str
    number: int
    node: int
    quantity: str


def parse_channel(name: str) -> Channel:
    """The channel of a MoorDyn output name (module documentation).

    Arguments:
        name: the name (any case).

    Returns:
        The channel.

    Raises:
        InvalidInputError: for a name of another kind, naming it and the supported forms.
    """
    text = name.strip().upper()
    if m := _LINE_END.fullmatch(text):
        if m.group(1):
            return Channel(name, "end", int(m.group(2)), 1 if m.group(1) == "FAIRTEN" else 0,
                           "tension")
        return Channel(name, "end", int(m.group(3)), 1 if m.group(4) == "B" else 0, "tension")
    if m := _NODE.fullmatch(text):
        quantity = "tension" if m.group(3) in ("T", "TEN") else m.group(3).lower()
        return Channel(name, "node", int(m.group(1)), int(m.group(2)), quantity)
    if m := _POINT.fullmatch(text):
        return Channel(name, "point", int(m.group(1)), 0, m.group(2).lower())
    raise InvalidInputError(
        f"output channel {name!r} is not supported: give FAIRTEN<n>, ANCHTEN<n>, "
        f"LINE<n>TENA/B, L<n>N<m> with PX..PZ, VX..VZ or T, or CON<n> (POINT<n>) with PX..PZ, "
        f"VX..VZ or FX..FZ", name="outputs", value=name)


def _checked(channel: Channel, count: int, what: str, last: int | None = None) -> None:
    if not 1 <= channel.number <= count:
        raise InvalidInputError(f"output channel {channel.name!r}: the model has {count} "
                                f"{what}s", name="outputs", value=channel.name)
    if last is not None and not 0 <= channel.node <= last:
        raise InvalidInputError(f"output channel {channel.name!r}: line {channel.number} has "
                                f"nodes 0 to {last}", name="outputs", value=channel.name)


def channel_values(run: Any, channel: Channel) -> np.ndarray:
    """The values of ``channel`` at the stored times of ``run`` (a
    :class:`vinculo.mooring.analysis.MooringRun`).

    Arguments:
        run: the run.
        channel: the channel.

    Returns:
        ``(times,)`` values.

    Raises:
        InvalidInputError: for a line, node or point the model does not have.
    """
    model = run.model
    axis = "xyz".index(channel.quantity[1]) if channel.quantity[:1] in ("p", "v", "f") else 0
    solution = run.solution
    if channel.kind == "end":
        _checked(channel, len(model.lines), "line")
        return np.asarray(run.end_tensions[:, channel.number - 1, channel.node])
    if channel.kind == "point" and channel.quantity[0] == "f":
        _checked(channel, len(model.points), "point")
        return _point_load(run, channel)[:, axis]
    if channel.kind == "point":
        _checked(channel, len(model.points), "point")
        index = model.points[channel.number - 1].index
        source = solution.positions if channel.quantity[0] == "p" else solution.velocities
        return np.asarray(source)[:, index, axis]
    line = model.lines[channel.number - 1] if 1 <= channel.number <= len(model.lines) else None
    _checked(channel, len(model.lines), "line",
             len(line.nodes) - 1 if line is not None else None)
    assert line is not None
    if channel.quantity == "tension":
        last = len(line.nodes) - 1
        if channel.node in (0, last):
            return np.asarray(run.end_tensions[:, channel.number - 1, 0 if channel.node == 0
                                               else 1])
        tensions = np.asarray(line.tensions(solution))
        return 0.5 * (tensions[:, channel.node - 1] + tensions[:, channel.node])
    source = solution.positions if channel.quantity[0] == "p" else solution.velocities
    return np.asarray(source)[:, line.nodes[channel.node], axis]


def _point_load(run: Any, channel: Channel) -> np.ndarray:
    """``(times, 3)``: the forces of the lines on a fixed or coupled point, with its weight and
    buoyancy (module documentation)."""
    file = run.model.file
    point = file.point(channel.number)
    if point.attachment == "free":
        raise InvalidInputError(
            f"output channel {channel.name!r}: point {point.id} is free; its net force (its "
            f"mass times its acceleration) is not given, only a fixed or coupled point's load",
            name="outputs", value=channel.name)
    o = file.options
    own = np.array([0.0, 0.0, (o.density * point.volume - point.mass) * o.gravity])
    load = np.zeros((len(run.times), 3)) + own
    for k, row in enumerate(file.lines):
        for end, attached in enumerate((row.attach_a, row.attach_b)):
            if attached == point.id:
                load = load + run.end_forces[:, k, end]
    return load
