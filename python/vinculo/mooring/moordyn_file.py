"""MoorDyn v2 input files: read them into a :class:`MoorDynFile`, write one back.

A MoorDyn v2 input file is plain text divided into sections, each opened by a header line of
dashes around a key phrase (``---- LINE TYPES ----``). A table section has two lines of column
names and units after its header, then one row per entry, values separated by white space;
``#`` starts a comment. The OPTIONS section has one ``value key [description]`` line per option.
The format is MoorDyn's (moordyn.readthedocs.io, "Input Files", "The V2 Input File").

What is read: LINE TYPES (name, diameter, mass per length, EA, BA or a negative damping ratio,
EI, Cd, Ca, CdAx, CaAx), POINTS (also spelled POINT PROPERTIES, CONNECTION PROPERTIES or
NODE PROPERTIES; attachments Fixed, Coupled/Vessel, Free/Point/Connect and Body<n>), BODIES
(Fixed and Coupled bodies, which place the points attached to them), LINES, OPTIONS (water
depth, density, gravity, seabed contact and friction, time step and MoorDyn's own simulation
settings) and OUTPUTS (kept for writing back). What is not supported yet raises a
:class:`~vinculo.errors.MooringFileError` that names the file, the line and the field: rods,
free bodies, failures, external loads, control channels, wave grids and dynamic currents,
viscoelastic stiffness, vortex-induced vibration.

Units are SI throughout (m, kg, N, s), as in the file.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring.channels import parse_channel
from vinculo.mooring.current_profile import PROFILE_FILE, CurrentProfile, read_current_profile
from vinculo.mooring.line import LineType
from vinculo.mooring.seafloor import Seafloor, read_seafloor
from vinculo.mooring.stiffness_curve import StiffnessCurve, read_stiffness_curve
from vinculo.mooring.wave_components import WAVE_FILE, WaveComponents, read_wave_frequencies

__all__ = [
    "ATTACHMENTS",
    "FileBody",
    "FileLine",
    "FileOptions",
    "FilePoint",
    "MoorDynFile",
    "format_moordyn",
    "parse_moordyn",
    "read_moordyn",
    "write_moordyn",
]

#: The point attachments vinculo supports, as stored in :attr:`FilePoint.attachment`.
ATTACHMENTS = ("fixed", "coupled", "free")

# The spellings MoorDyn accepts for each supported attachment (compared in lower case).
_ATTACHMENT_NAMES = {
    "fixed": "fixed",
    "fix": "fixed",
    "anchor": "fixed",
    "coupled": "coupled",
    "vessel": "coupled",
    "vess": "coupled",
    "ves": "coupled",
    "cpld": "coupled",
    "free": "free",
    "point": "free",
    "connect": "free",
    "con": "free",
}

# Section key phrases (upper case, spaces collapsed) -> section kind.
_SECTIONS = {
    "LINE TYPES": "line_types",
    "LINE DICTIONARY": "line_types",
    "ROD TYPES": "rod_types",
    "ROD DICTIONARY": "rod_types",
    "BODIES": "bodies",
    "BODY LIST": "bodies",
    "BODY PROPERTIES": "bodies",
    "RODS": "rods",
    "ROD LIST": "rods",
    "ROD PROPERTIES": "rods",
    "POINTS": "points",
    "POINT LIST": "points",
    "POINT PROPERTIES": "points",
    "CONNECTION PROPERTIES": "points",
    "CONNECTIONS": "points",
    "NODE PROPERTIES": "points",
    "LINES": "lines",
    "LINE LIST": "lines",
    "LINE PROPERTIES": "lines",
    "OPTIONS": "options",
    "SOLVER OPTIONS": "options",
    "OUTPUTS": "outputs",
    "OUTPUT": "outputs",
    "OUTPUT LIST": "outputs",
    "FAILURE": "failure",
    "FAILURES": "failure",
    "CONTROL": "control",
    "EXTERNAL LOADS": "external_loads",
}

# Sections whose rows vinculo cannot model yet, and what they hold.
_UNSUPPORTED_SECTIONS = {
    "rod_types": "rod types",
    "rods": "rods",
    "failure": "line failures",
    "control": "control channels",
    "external_loads": "external loads",
}


@dataclass(frozen=True)
class FilePoint:
    """A row of the POINTS section.

    Arguments:
        id: the point's number (1, 2, ... in file order).
        attachment: ``"fixed"`` (an anchor), ``"coupled"`` (moved by the caller: MoorDyn's
            Coupled or Vessel) or ``"free"`` (a free point: MoorDyn's Free, Point or Connect).
        position: (x, y, z) in m, z up, the water surface at z = 0; for a free point, the
            initial guess of its position.
        mass: a clump weight's mass (kg).
        volume: a float's displaced volume (m^3).
        cda: drag coefficient times projected area (m^2).
        ca: added-mass coefficient (on the displaced volume).
        body: the body the point is attached to (``Body<n>``), whose attachment it then has;
            None for a point of its own.
        relative: for a point on a body, its position in the body's frame as the file gives
            it (``position`` is then where the body places it).
    """

    id: int
    attachment: str
    position: tuple[float, float, float]
    mass: float = 0.0
    volume: float = 0.0
    cda: float = 0.0
    ca: float = 0.0
    body: int | None = None
    relative: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class FileBody:
    """A row of the BODIES section: a Fixed or Coupled rigid body, which places the points
    attached to it (``Body<n>`` in the POINTS section).

    A point at ``r`` in the body's frame is at ``position + R r``, with
    ``R = Rx(roll) Ry(pitch) Rz(yaw)`` (MoorDyn-C's composition of the body's angles, checked
    against the point positions MoorDyn 2.7.2 reports). A Coupled body's pose in a run comes
    from the motion file (:func:`vinculo.mooring.motion.read_motion`). The body's own mass,
    inertia, volume and drag act on a Free body only, which vinculo does not model yet: they
    are kept as written.

    Arguments:
        id: the body's number (1, 2, ... in file order).
        attachment: ``"fixed"`` or ``"coupled"`` (MoorDyn's Coupled or Vessel).
        position: the reference point (X0, Y0, Z0), m.
        rotation: roll, pitch and yaw (r0, p0, y0), degrees.
        properties: the Mass, CG, I, Volume, CdA and Ca columns as written.
    """

    id: int
    attachment: str
    position: tuple[float, float, float]
    rotation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    properties: tuple[str, ...] = ("0", "0", "0", "0", "0", "0")

    def rotation_matrix(self) -> tuple[tuple[float, float, float], ...]:
        """``R = Rx(roll) Ry(pitch) Rz(yaw)``, rows."""
        (cr, sr), (cp, sp), (cy, sy) = (
            (math.cos(math.radians(a)), math.sin(math.radians(a))) for a in self.rotation)
        return ((cp * cy, -cp * sy, sp),
                (cr * sy + sr * sp * cy, cr * cy - sr * sp * sy, -sr * cp),
                (sr * sy - cr * sp * cy, sr * cy + cr * sp * sy, cr * cp))

    def place(self, relative: tuple[float, float, float]) -> tuple[float, float, float]:
        """The position of the point at ``relative`` in the body's frame (m)."""
        return self.place_all([relative])[0]

    def place_all(self, relatives: Sequence[tuple[float, float, float]]
                  ) -> list[tuple[float, float, float]]:
        """:meth:`place` of each point at ``relatives``, the rotation computed once."""
        rows = self.rotation_matrix()
        return [tuple(  # type: ignore[misc]
            self.position[i] + sum(rows[i][k] * relative[k] for k in range(3))
            for i in range(3)) for relative in relatives]


@dataclass(frozen=True)
class FileLine:
    """A row of the LINES section.

    Arguments:
        id: the line's number (1, 2, ... in file order).
        line_type: the name of its LINE TYPES row.
        attach_a: the number of the point of end A (MoorDyn's anchor end, node 0).
        attach_b: the number of the point of end B (the fairlead end, node N).
        unstretched_length: the unstretched length (m).
        segments: the number of segments N (the line has N + 1 nodes).
        outputs: MoorDyn's output flags (``"-"``: none); kept for writing back.
    """

    id: int
    line_type: str
    attach_a: int
    attach_b: int
    unstretched_length: float
    segments: int
    outputs: str = "-"


@dataclass(frozen=True)
class FileOptions:
    """The OPTIONS section, with MoorDyn-C's defaults for the options a file omits.

    Arguments:
        depth: water depth WtrDpth (m): the flat seabed is at z = -depth.
        density: water density rhoW (kg/m^3).
        gravity: gravitational acceleration g (m/s^2).
        kbot: seabed stiffness per unit area kBot (Pa/m).
        cbot: seabed damping per unit area cBot (Pa s/m).
        friction: seabed friction coefficient FrictionCoefficient (MoorDyn-C; MoorDyn-F's MU_KT).
        axial_friction: MoorDyn-F's axial friction coefficient MU_KA (None: not given).
        friction_damping: FricDamp (MoorDyn-F's CV): the velocity scale of the regularised
            friction (s/m).
        static_dynamic_scale: StatDynFricScale (MoorDyn-F's MC): static over dynamic friction.
        time_step: dtM, MoorDyn's time step (s); None when the file gives none.
        seafloor: the seabed's heights from the file named by SeafloorFile (MoorDyn-C's 3D
            seafloor) or given as WtrDpth (MoorDyn-F's bathymetry file)
            (:func:`vinculo.mooring.seafloor.read_seafloor`; None: the flat seabed at
            z = -depth). Without a numeric WtrDpth, the depth is the grid's average depth, as
            MoorDyn's.
        current: the steady current of ``Currents 1``, read from ``current_profile.txt``
            beside the input file (:mod:`vinculo.mooring.current_profile`; None: still water).
        waves: the wave components of ``WaveKin 7``, read from ``wave_frequencies.txt``
            beside the input file (:mod:`vinculo.mooring.wave_components`; None: no waves).
        wave_ramp: MoorDyn's ``waveKin_rampT``, the time over which the waves grow (s).
        settings: MoorDyn's simulation settings that do not change the model (writeLog,
            tScheme, CFL, dtOut, the initial-condition settings dtIC, TmaxIC, CdScaleIC,
            threshIC, ...), as (key, text) pairs in file order, kept for writing back.
    """

    depth: float = 0.0
    density: float = 1025.0
    gravity: float = 9.80665
    kbot: float = 3.0e6
    cbot: float = 3.0e5
    friction: float = 0.0
    axial_friction: float | None = None
    friction_damping: float = 200.0
    static_dynamic_scale: float = 1.0
    time_step: float | None = None
    settings: tuple[tuple[str, str], ...] = ()
    seafloor: Seafloor | None = None
    current: CurrentProfile | None = None
    waves: WaveComponents | None = None
    wave_ramp: float = 0.0


@dataclass(frozen=True)
class MoorDynFile:
    """The content of a MoorDyn v2 input file.

    Arguments:
        line_types: the LINE TYPES rows, by name, in file order.
        points: the POINTS rows, in file order (point ``k`` is ``points[k - 1]``).
        lines: the LINES rows, in file order.
        options: the OPTIONS section.
        title: the free text before the first section (without its header line).
        outputs: the OUTPUTS channel names (:mod:`vinculo.mooring.channels`): a run writes
            them (``channels.csv``), and they are written back.
        path: the file read (None for a model parsed from text or built in code).
        bodies: the BODIES rows, in file order (body ``k`` is ``bodies[k - 1]``).
    """

    line_types: dict[str, LineType]
    points: tuple[FilePoint, ...]
    lines: tuple[FileLine, ...]
    options: FileOptions = field(default_factory=FileOptions)
    title: str = ""
    outputs: tuple[str, ...] = ()
    path: Path | None = None
    bodies: tuple[FileBody, ...] = ()

    def point(self, number: int) -> FilePoint:
        """The point with MoorDyn number ``number``.

        Arguments:
            number: the point's ID (1-based, as in the file).

        Returns:
            Its row.

        Raises:
            MooringFileError: when there is no such point.
        """
        if not 1 <= number <= len(self.points):
            raise MooringFileError(
                f"{self.path or 'the model'}: there is no point {number} (the file has "
                f"{len(self.points)} points)",
                file=str(self.path) if self.path else None, field="point", value=number,
            )
        return self.points[number - 1]

    def coupled_points(self) -> list[FilePoint]:
        """The coupled (Vessel/Coupled) points, in file order: the order of MoorDyn's coupled
        degrees of freedom and of the columns of a motion file.

        Returns:
            The coupled points' rows.
        """
        return [p for p in self.points if p.attachment == "coupled"]

    def coupled_bodies(self) -> list[FileBody]:
        """The Coupled bodies, in file order: their six degrees of freedom come first in
        MoorDyn's coupled state and in a motion file.

        Returns:
            The coupled bodies' rows.
        """
        return [b for b in self.bodies if b.attachment == "coupled"]


# --------------------------------------------------------------------------------------------
# Reading


@dataclass
class _Line:
    number: int  # 1-based line number in the file
    text: str  # without the comment


def _error(path: str, line: int | None, field_name: str, message: str, value: object = None
           ) -> MooringFileError:
    where = f"{path}, line {line}" if line is not None else path
    return MooringFileError(f"{where}: {field_name}: {message}", file=path, line=line,
                            field=field_name, value=value)


def _section_kind(text: str) -> str | None:
    """The kind of section a header line opens, None when it is not a header ("" for a header
    line with no known key phrase, such as MoorDyn's closing line)."""
    stripped = text.strip()
    if not stripped.startswith("--"):
        return None
    phrase = re.sub(r"\s+", " ", stripped.strip("-").strip()).upper()
    for key, kind in _SECTIONS.items():
        if phrase == key or phrase.startswith(key + " ") or phrase.endswith(" " + key):
            return kind
    return ""


def _number(path: str, line: _Line, field_name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise _error(path, line.number, field_name, f"{text!r} is not a number", text) from None
    if not math.isfinite(value):
        raise _error(path, line.number, field_name, f"{text!r} is not a finite number", text)
    return value


def _whole(path: str, line: _Line, field_name: str, text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise _error(path, line.number, field_name, f"{text!r} is not a whole number",
                     text) from None


def _positive(path: str, line: _Line, field_name: str, value: float, allow_zero: bool = False
              ) -> float:
    if value < 0.0 or (value == 0.0 and not allow_zero):
        need = ">= 0" if allow_zero else "> 0"
        raise _error(path, line.number, field_name, f"{value:g} must be {need}", value)
    return value


def _stiffness(path: str, line: _Line, field_name: str, text: str, what: str) -> float:
    if "|" in text:
        raise _error(path, line.number, field_name,
                     f"{text!r}: {what} with static and dynamic values (viscoelastic lines) "
                     f"is not supported yet; give one number", text)
    try:
        float(text)
    except ValueError:
        raise _error(path, line.number, field_name,
                     f"{text!r} is not a number (a file name here, {what} from a table of a "
                     f"non-linear line, is not supported yet)", text) from None
    return _number(path, line, field_name, text)


def _split_sections(path: str, text: str) -> Iterator[tuple[str, _Line, list[_Line]]]:
    """(kind, header line, body lines) of each section; the front matter has kind "title"."""
    kind, header, body = "title", _Line(0, ""), []
    for number, raw in enumerate(text.splitlines(), start=1):
        content = raw.split("#", 1)[0].rstrip()
        found = _section_kind(content)
        if found == "" and number == 1:
            continue  # the optional "--- MoorDyn Input File ---" line opening the front matter
        if found is None:
            body.append(_Line(number, content))
            continue
        yield kind, header, body
        kind, header, body = (found or "end"), _Line(number, content), []
    yield kind, header, body


# MoorDyn v1's table layouts, told by their column names, and what v2's are instead (MoorDyn's
# docs/inputs.rst, "The V1 Input File"; MoorDyn-C v2 does not read them either).
_V1_LAYOUTS = {
    "line_types": (lambda names: {"CAN", "CDN"} <= names and "EI" not in names,
                   "LINE TYPES: Name Diam MassDen EA BA/-zeta Can Cat Cdn Cdt",
                   "TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx (EI 0 for none, "
                   "Cd = Cdn, Ca = Can, CdAx = Cdt, CaAx = Cat)"),
    "points": (lambda names: "FX" in names,
               "POINTS: Node Type X Y Z M V FX FY FZ CdA CA",
               "ID Attachment X Y Z Mass Volume CdA Ca (without FX FY FZ; Connect is Free, "
               "Vessel is Coupled)"),
    "lines": (lambda names: "NODEANCH" in names or "NODEFAIR" in names,
              "LINES: Line LineType UnstrLen NumSegs NodeAnch NodeFair",
              "ID LineType AttachA AttachB UnstrLen NumSegs (the ends before the length)"),
}


# FAST 8's count lines at the top of its MoorDyn v1 tables.
_V1_COUNTS = {"NTYPES", "NCONNECTS", "NLINES", "NPOINTS", "NNODES"}


def _reject_v1_layout(path: str, kind: str, body: list[_Line]) -> None:
    """A MooringFileError when the table's column names are MoorDyn v1's, whose columns lie in
    another order (read as v2's, the numbers would go to the wrong fields)."""
    lines = [ln for ln in body if ln.text.strip()]
    if kind not in _V1_LAYOUTS or not lines:
        return
    first = lines[0].text.split()
    if len(first) >= 2 and _is_number(first[0]) and first[1].upper() in _V1_COUNTS:
        # FAST 8's MoorDyn v1: a count line before the column names.
        raise _error(path, lines[0].number, first[1],
                     f"MoorDyn v1's count line ({first[1]}, FAST 8's layout); vinculo reads "
                     f"MoorDyn v2 files, as MoorDyn v2 does: remove it", lines[0].text.strip())
    names = {word.upper() for word in first}
    matches, v1, v2 = _V1_LAYOUTS[kind]
    if matches(names):
        raise _error(path, lines[0].number, v1.split(":")[0],
                     f"MoorDyn v1's columns ({v1}); vinculo reads MoorDyn v2 files, as "
                     f"MoorDyn v2 does: write the columns {v2}", lines[0].text.strip())


def _table_rows(body: list[_Line]) -> list[tuple[_Line, list[str]]]:
    """The entries of a table section: after the column-name and unit lines, the non-blank
    lines split into fields."""
    lines = [ln for ln in body if ln.text.strip()]
    return [(ln, ln.text.split()) for ln in lines[2:]]


def _check_columns(path: str, line: _Line, fields: list[str], names: tuple[str, ...],
                   section: str) -> None:
    if len(fields) < len(names):
        missing = names[len(fields)]
        raise _error(path, line.number, missing,
                     f"the {section} row has {len(fields)} values; it needs "
                     f"{len(names)} ({' '.join(names)})", " ".join(fields))


_LINE_TYPE_COLUMNS = ("TypeName", "Diam", "Mass/m", "EA", "BA/-zeta", "EI", "Cd", "Ca", "CdAx",
                      "CaAx")


def _line_type(path: str, line: _Line, fields: list[str]) -> LineType:
    _check_columns(path, line, fields, _LINE_TYPE_COLUMNS, "LINE TYPES")
    cols = dict(zip(_LINE_TYPE_COLUMNS, fields, strict=False))
    if len(fields) > len(_LINE_TYPE_COLUMNS):
        lift = _number(path, line, "Cl", fields[10])
        if lift != 0.0:
            raise _error(path, line.number, "Cl",
                         f"{lift:g}: vortex-induced vibration (a non-zero lift coefficient) is "
                         f"not supported yet; give 0 or leave the column out", lift)
    name = cols["TypeName"]
    diameter = _positive(path, line, "Diam", _number(path, line, "Diam", cols["Diam"]))
    mass = _positive(path, line, "Mass/m", _number(path, line, "Mass/m", cols["Mass/m"]))
    curve = None
    if _is_number(cols["EA"]) or "|" in cols["EA"]:
        ea = _positive(path, line, "EA", _stiffness(path, line, "EA", cols["EA"], "EA"))
    else:
        # MoorDyn's nonlinear EA: a strain-tension table beside the input file.
        curve = _curve(path, line, cols["EA"])
        ea = curve.stiffest
    ba = _stiffness(path, line, "BA/-zeta", cols["BA/-zeta"], "BA")
    if curve is not None and ba < 0.0:
        raise _error(path, line.number, "BA/-zeta",
                     f"{ba:g}: a damping ratio with a tabulated EA is not supported (the ratio "
                     f"needs one EA); give BA in N s", ba)
    values = {}
    for column in ("EI", "Cd", "Ca", "CdAx", "CaAx"):
        values[column] = _positive(path, line, column,
                                   _number(path, line, column, cols[column]), allow_zero=True)
    return LineType(name=name, diameter=diameter, mass_per_length=mass, ea=ea, ba=ba,
                        ei=values["EI"], cd=values["Cd"], ca=values["Ca"],
                        cdax=values["CdAx"], caax=values["CaAx"], ea_curve=curve)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _curve(path: str, line: _Line, text: str) -> StiffnessCurve:
    """The strain-tension table named in a line type's EA: beside the input file, or at the
    path given (MoorDyn-C's rule)."""
    given = Path(text.strip('"'))
    folder = Path(path).parent if Path(path).is_file() else Path.cwd()
    candidate = given if given.is_absolute() else folder / given
    if not candidate.is_file():
        raise _error(path, line.number, "EA",
                     f"{text!r}: no such strain-tension file (looked for {str(candidate)!r})",
                     text)
    return read_stiffness_curve(candidate)


def _numbered(path: str, line: _Line, fields: list[str], columns: tuple[str, ...],
              section: str, what: tuple[str, str], expected_id: int) -> int:
    """The ID of a row of a numbered table (points, bodies, lines: ``what``, singular and
    plural), its columns checked and its number the next one."""
    _check_columns(path, line, fields, columns, section)
    number = _whole(path, line, "ID", fields[0])
    if number != expected_id:
        raise _error(path, line.number, "ID",
                     f"{what[0]} {number}: {what[1]} must be numbered 1, 2, ... in order "
                     f"(expected {expected_id})", number)
    return number


_POINT_COLUMNS = ("ID", "Attachment", "X", "Y", "Z", "Mass", "Volume", "CdA", "Ca")


def _point(path: str, line: _Line, fields: list[str], expected_id: int,
           bodies: dict[int, FileBody]) -> FilePoint:
    number = _numbered(path, line, fields, _POINT_COLUMNS, "POINTS", ("point", "points"),
                       expected_id)
    word = fields[1]
    attachment = _ATTACHMENT_NAMES.get(word.lower())
    on_body = re.fullmatch(r"(?i)body(\d+)", word)
    body = bodies.get(int(on_body.group(1))) if on_body else None
    if on_body and body is None:
        raise _error(path, line.number, "Attachment",
                     f"{word!r}: there is no body {on_body.group(1)} in a BODIES section "
                     f"before POINTS", word)
    if attachment is None and body is None:
        if re.fullmatch(r"(?i)turbine\d*", word):
            raise _error(path, line.number, "Attachment",
                         f"{word!r}: points attached to turbines are not supported yet; use "
                         f"Fixed, Coupled (Vessel), Free or a body", word)
        raise _error(path, line.number, "Attachment",
                     f"{word!r} is not a point attachment: use Fixed, Coupled (or Vessel), "
                     f"Free (or Point, Connect) or Body<n>", word)
    x, y, z = (_number(path, line, name, fields[k]) for k, name in zip((2, 3, 4), "XYZ",
                                                                        strict=True))
    mass, volume, cda, ca = (
        _positive(path, line, name, _number(path, line, name, fields[k]), allow_zero=True)
        for k, name in zip((5, 6, 7, 8), ("Mass", "Volume", "CdA", "Ca"), strict=True)
    )
    if body is not None:
        return FilePoint(id=number, attachment=body.attachment, position=body.place((x, y, z)),
                         mass=mass, volume=volume, cda=cda, ca=ca, body=body.id,
                         relative=(x, y, z))
    return FilePoint(id=number, attachment=str(attachment), position=(x, y, z), mass=mass,
                     volume=volume, cda=cda, ca=ca)


_BODY_COLUMNS = ("ID", "Attachment", "X0", "Y0", "Z0", "r0", "p0", "y0", "Mass", "CG", "I",
                 "Volume", "CdA", "Ca")


def _body(path: str, line: _Line, fields: list[str], expected_id: int) -> FileBody:
    number = _numbered(path, line, fields, _BODY_COLUMNS, "BODIES", ("body", "bodies"),
                       expected_id)
    word = fields[1]
    attachment = _ATTACHMENT_NAMES.get(word.lower())
    if attachment == "free":
        raise _error(path, line.number, "Attachment",
                     f"{word!r}: free bodies are not supported yet; vinculo reads Fixed and "
                     f"Coupled (Vessel) bodies, which place their points (statics, stiffness, "
                     f"offset curves)", word)
    if attachment is None:
        raise _error(path, line.number, "Attachment",
                     f"{word!r} is not a body attachment: use Fixed or Coupled (or Vessel)",
                     word)
    pose = [_number(path, line, name, fields[k]) for k, name in enumerate(_BODY_COLUMNS[2:8], 2)]
    return FileBody(id=number, attachment=attachment, position=(pose[0], pose[1], pose[2]),
                    rotation=(pose[3], pose[4], pose[5]), properties=tuple(fields[8:14]))


_LINE_COLUMNS = ("ID", "LineType", "AttachA", "AttachB", "UnstrLen", "NumSegs")


def _attach(path: str, line: _Line, field_name: str, text: str) -> int:
    if re.fullmatch(r"(?i)r\d+[ab]", text):
        raise _error(path, line.number, field_name,
                     f"{text!r}: lines attached to rod ends are not supported yet; attach "
                     f"lines to points", text)
    number = _whole(path, line, field_name, text)
    if number < 1:
        raise _error(path, line.number, field_name, f"{number}: point numbers start at 1",
                     number)
    return number


def _line(path: str, line: _Line, fields: list[str], expected_id: int) -> FileLine:
    number = _numbered(path, line, fields, _LINE_COLUMNS, "LINES", ("line", "lines"),
                       expected_id)
    attach_a = _attach(path, line, "AttachA", fields[2])
    attach_b = _attach(path, line, "AttachB", fields[3])
    length = _positive(path, line, "UnstrLen", _number(path, line, "UnstrLen", fields[4]))
    segments = _whole(path, line, "NumSegs", fields[5])
    if segments < 1:
        raise _error(path, line.number, "NumSegs", f"{segments}: give at least 1 segment",
                     segments)
    outputs = fields[6] if len(fields) > 6 else "-"
    return FileLine(id=number, line_type=fields[1], attach_a=attach_a, attach_b=attach_b,
                    unstretched_length=length, segments=segments, outputs=outputs)


# Options that change the model: key (lower case) -> FileOptions field.
_MODEL_OPTIONS = {
    "wtrdpth": "depth",
    "depth": "depth",
    "rhow": "density",
    "rho": "density",
    "wtrdnsty": "density",
    "g": "gravity",
    "gravity": "gravity",
    "kbot": "kbot",
    "kb": "kbot",
    "cbot": "cbot",
    "cb": "cbot",
    "frictioncoefficient": "friction",
    "mu_kt": "friction",
    "mu_ka": "axial_friction",
    "fricdamp": "friction_damping",
    "cv": "friction_damping",
    "statdynfricscale": "static_dynamic_scale",
    "mc": "static_dynamic_scale",
    "dtm": "time_step",
    "wavekin_rampt": "wave_ramp",
}

# MoorDyn's settings of its own run that do not change the model: kept, written back.
_SETTINGS = {
    "writelog", "tscheme", "cfl", "dtout", "dtic", "tmaxic", "cdscaleic", "threshic",
    "icdfac", "icthresh", "ictmax", "icgendynamic", "disableoutput", "disableouttime",
    "writeunits", "echo", "outswitch", "inertialf", "inertialf_rampt", "fileic",
}

# Options of features not supported yet: key -> what it asks for. A zero (or empty) value
# switches the feature off and is accepted.
_UNSUPPORTED_OPTIONS = {
    "waterkin": "water kinematics",
    "dtwave": "wave kinematics",
    "unifycurrentgrid": None,
}


_OFF = ("0", "0.0", "", "-", '""', "none")


def _seafloor(path: str, line: _Line, key: str, text: str) -> Seafloor:
    """The seafloor file ``text`` of option ``key``: relative to the input file's folder, or
    to the working directory (where MoorDyn looks)."""
    given = Path(text.strip('"'))
    candidates = [given] if given.is_absolute() else [Path(path).parent / given, given]
    for candidate in candidates:
        if candidate.is_file():
            return read_seafloor(candidate)
    looked = " and ".join(repr(str(c)) for c in dict.fromkeys(candidates))
    raise _error(path, line.number, key,
                 f"{text!r}: no such seafloor file (looked for {looked})", text)


def _beside(path: str, line: _Line, key: str, text: str, modes: dict[float, str],
            what: str) -> Path | None:
    """The file that option ``key`` = ``text`` reads beside the input file: None for mode 0,
    ``modes[mode]`` for a supported mode, an error for the others (``what`` they are) or for a
    missing file."""
    mode = _number(path, line, key, text)
    if mode == 0.0:
        return None
    if mode not in modes:
        given = ", ".join(f"{m:g} ({f})" for m, f in modes.items())
        raise _error(path, line.number, key,
                     f"{text!r}: only {what} are supported yet ({given}); give 0 or "
                     f"{' or '.join(f'{m:g}' for m in modes)}", text)
    folder = Path(path).parent if Path(path).is_file() else Path.cwd()
    found = folder / modes[mode]
    if not found.is_file():
        raise _error(path, line.number, key,
                     f"{text!r}: {key} {mode:g} reads {modes[mode]} beside the input file; "
                     f"there is no {str(found)!r}", text)
    return found


def _current(path: str, line: _Line, key: str, text: str) -> CurrentProfile | None:
    """The current of option ``Currents``: none for 0, the profile beside the input file for
    1 (MoorDyn-C's steady current), an error for the others."""
    found = _beside(path, line, key, text, {1.0: PROFILE_FILE},
                    "steady currents (not dynamic or gridded ones)")
    return None if found is None else read_current_profile(found)


def _waves(path: str, line: _Line, key: str, text: str) -> WaveComponents | None:
    """The waves of option ``WaveKin``: none for 0, the components beside the input file for
    7 (MoorDyn-C's component summing), an error for the others."""
    found = _beside(path, line, key, text, {7.0: WAVE_FILE},
                    "waves summed from their components (not wave grids or external waves)")
    return None if found is None else read_wave_frequencies(found)


def _options(path: str, body: list[_Line]) -> FileOptions:
    values: dict[str, float] = {}
    settings: list[tuple[str, str]] = []
    seafloor: Seafloor | None = None
    current: CurrentProfile | None = None
    waves: WaveComponents | None = None
    for line in body:
        fields = line.text.split()
        if not fields:
            continue
        if len(fields) < 2:
            raise _error(path, line.number, fields[0],
                         "an option line is 'value key [description]'; the key is missing",
                         fields[0])
        text, key = fields[0], fields[1]
        lower = key.lower()
        if lower in _MODEL_OPTIONS:
            name = _MODEL_OPTIONS[lower]
            if name == "depth":
                try:
                    float(text)
                except ValueError:
                    # MoorDyn-F's bathymetry file in place of the depth.
                    if seafloor is not None:
                        raise _error(path, line.number, key, f"{text!r}: a second seafloor "
                                     f"(SeafloorFile gives one); give one of them",
                                     text) from None
                    seafloor = _seafloor(path, line, key, text)
                    continue
            value = _number(path, line, key, text)
            _positive(path, line, key, value,
                      allow_zero=name not in ("depth", "density", "gravity", "time_step"))
            values[name] = value
        elif lower in _SETTINGS:
            settings.append((key, text))
        elif lower == "currents":
            current = _current(path, line, key, text)
        elif lower == "wavekin":
            waves = _waves(path, line, key, text)
        elif lower == "seafloorfile":
            if text.lower() not in _OFF:
                if seafloor is not None:
                    raise _error(path, line.number, key, f"{text!r}: a second seafloor "
                                 f"(WtrDpth gives one); give one of them", text)
                seafloor = _seafloor(path, line, key, text)
        elif lower in _UNSUPPORTED_OPTIONS:
            what = _UNSUPPORTED_OPTIONS[lower]
            if what is None:
                settings.append((key, text))
                continue
            off = text in _OFF or lower == "dtwave"
            if not off:
                raise _error(path, line.number, key,
                             f"{text!r}: {what} are not supported yet (still water only); "
                             f"remove the option or set it to 0", text)
            settings.append((key, text))
        else:
            known = sorted({*(_MODEL_OPTIONS), *(_SETTINGS)})
            raise _error(path, line.number, key,
                         f"unknown option {key!r}; known options: {', '.join(known)}", key)
    if seafloor is not None and "depth" not in values:
        values["depth"] = seafloor.mean_depth
    if waves is not None and not values.get("depth", 0.0) > 0.0:
        raise MooringFileError(f"{path}: WtrDpth: waves (WaveKin 7) need a water depth > 0",
                               file=path, line=None, field="WtrDpth", value=values.get("depth"))
    return FileOptions(**values, settings=tuple(settings), seafloor=seafloor, current=current,
                       waves=waves)


def parse_moordyn(text: str, path: str | Path = "<text>") -> MoorDynFile:
    """Read the text of a MoorDyn v2 input file.

    Arguments:
        text: the file's content.
        path: the file's name, for error messages (and :attr:`MoorDynFile.path`).

    Returns:
        The file's content.

    Raises:
        MooringFileError: for a malformed value, a missing section or column, a reference to
            an unknown line type or point, or a feature that vinculo does not support yet; the
            message (and the ``file``, ``line`` and ``field`` attributes) says where.
    """
    name = str(path)
    title = ""
    line_types: dict[str, LineType] = {}
    points: list[FilePoint] = []
    bodies: dict[int, FileBody] = {}
    lines: list[FileLine] = []
    options = FileOptions()
    outputs: list[str] = []
    seen: dict[str, int] = {}
    line_type_rows: dict[str, int] = {}
    for kind, header, body in _split_sections(name, text):
        if kind == "title":
            title = "\n".join(ln.text for ln in body).strip("\n")
            continue
        if kind == "end":
            rows = [ln for ln in body if ln.text.strip()]
            if rows:
                raise _error(name, header.number, header.text.strip("- ") or header.text,
                             "not a MoorDyn section vinculo knows (LINE TYPES, BODIES, POINTS, "
                             "LINES, OPTIONS, OUTPUTS; ROD TYPES and RODS are not supported "
                             "yet)", header.text)
            continue
        if kind in seen:
            raise _error(name, header.number, header.text.strip("- "),
                         f"a second {header.text.strip('- ')} section (the first is on line "
                         f"{seen[kind]})", header.text)
        seen[kind] = header.number
        _reject_v1_layout(name, kind, body)
        if kind in _UNSUPPORTED_SECTIONS:
            rows = _table_rows(body)
            if rows:
                line, fields = rows[0]
                raise _error(name, line.number, header.text.strip("- "),
                             f"{_UNSUPPORTED_SECTIONS[kind]} are not supported yet; vinculo "
                             f"reads lines between points (remove the section)", fields[0])
        elif kind == "line_types":
            for line, fields in _table_rows(body):
                lt = _line_type(name, line, fields)
                if lt.name in line_types:
                    raise _error(name, line.number, "TypeName",
                                 f"line type {lt.name!r} is defined twice (first on line "
                                 f"{line_type_rows[lt.name]})", lt.name)
                line_types[lt.name] = lt
                line_type_rows[lt.name] = line.number
        elif kind == "bodies":
            for line, fields in _table_rows(body):
                row = _body(name, line, fields, len(bodies) + 1)
                bodies[row.id] = row
        elif kind == "points":
            for line, fields in _table_rows(body):
                points.append(_point(name, line, fields, len(points) + 1, bodies))
        elif kind == "lines":
            for line, fields in _table_rows(body):
                ln = _line(name, line, fields, len(lines) + 1)
                if ln.line_type not in line_types:
                    known = ", ".join(line_types) or "none"
                    raise _error(name, line.number, "LineType",
                                 f"{ln.line_type!r} is not a line type of the LINE TYPES "
                                 f"section (defined: {known})", ln.line_type)
                for end, number in (("AttachA", ln.attach_a), ("AttachB", ln.attach_b)):
                    if number > len(points):
                        raise _error(name, line.number, end,
                                     f"point {number} is not in the POINTS section (it has "
                                     f"{len(points)} points, which must come before LINES)",
                                     number)
                if ln.attach_a == ln.attach_b:
                    raise _error(name, line.number, "AttachB",
                                 f"both ends of line {ln.id} are attached to point "
                                 f"{ln.attach_a}", ln.attach_b)
                lines.append(ln)
        elif kind == "options":
            options = _options(name, body)
        elif kind == "outputs":
            rows = [ln for ln in body if ln.text.strip() and ln.text.strip().upper() != "END"]
            for ln in rows:
                try:
                    parse_channel(ln.text.strip())
                except InvalidInputError as exc:
                    raise _error(name, ln.number, "OUTPUTS", str(exc),
                                 ln.text.strip()) from None
            outputs = [ln.text.strip() for ln in rows]
    if not lines:
        raise _error(name, None, "LINES",
                     "the file has no LINES section or no line in it; a MoorDyn model needs "
                     "at least one line", None)
    return MoorDynFile(line_types=line_types, points=tuple(points), lines=tuple(lines),
                       options=options, title=title, outputs=tuple(outputs),
                       path=Path(path) if name != "<text>" else None,
                       bodies=tuple(bodies.values()))


def read_moordyn(path: str | Path) -> MoorDynFile:
    """Read a MoorDyn v2 input file.

    Arguments:
        path: the file (MoorDyn's usual suffixes are .txt and .dat).

    Returns:
        The file's content.

    Raises:
        MooringFileError: when the file cannot be read, or for anything
            :func:`parse_moordyn` rejects.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise MooringFileError(f"cannot read the MoorDyn file {str(path)!r}: {exc.strerror}",
                               file=str(path), line=None, field=None, value=None) from None
    return parse_moordyn(text, path)


# --------------------------------------------------------------------------------------------
# Writing


def _g(value: float) -> str:
    """A number as text that reads back to the same float."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") and "e" not in text else text


def _row(values: list[str], widths: list[int]) -> str:
    return " ".join(v.ljust(w) for v, w in zip(values, widths, strict=True)).rstrip()


def _table(names: list[str], units: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[k]) for r in [names, units, *rows]) for k in range(len(names))]
    return [_row(names, widths), _row(units, widths)] + [_row(r, widths) for r in rows]


def _header(phrase: str) -> str:
    return f"{'-' * 22} {phrase} {'-' * max(4, 50 - len(phrase))}"


_ATTACHMENT_WORDS = {"fixed": "Fixed", "coupled": "Coupled", "free": "Free"}


def _ea_text(line_type: LineType, curve_paths: dict[str, str] | None) -> str:
    """The EA column of a line type: the number, or the file of its tension-strain curve."""
    curve = line_type.ea_curve
    if curve is None:
        return _g(line_type.ea)
    if curve_paths and line_type.name in curve_paths:
        return curve_paths[line_type.name]
    if curve.path is None:
        raise InvalidInputError(
            f"line type {line_type.name!r}: its stiffness curve was built in code and has no "
            f"file: give curve_paths (write_moordyn writes it beside the file)",
            name="curve_paths", value=None)
    # MoorDyn looks for the file beside the input file, whatever the path says.
    return Path(curve.path).name


def format_moordyn(model: MoorDynFile, seafloor_path: str | Path | None = None,
                   curve_paths: dict[str, str] | None = None) -> str:
    """The text of a MoorDyn v2 input file for ``model``.

    Arguments:
        model: the model to write.
        seafloor_path: the seafloor file the text names in SeafloorFile (default: the one the
            model's seafloor was read from, absolute).
        curve_paths: the strain-tension file each nonlinear line type names in its EA column,
            by type name (default: the name of the file its curve was read from, which MoorDyn
            looks for beside the input file).

    Returns:
        The file's text; :func:`parse_moordyn` reads it back to an equal model.

    Raises:
        InvalidInputError: for a model with a seafloor built in code (or read from MoorDyn-F's
            bathymetry file, which MoorDyn-C does not read) and no ``seafloor_path``, or a
            stiffness curve built in code and no ``curve_paths`` (:func:`write_moordyn` writes
            them beside the file).
    """
    out = [_header("MoorDyn Input File")]
    out += (model.title or "MoorDyn v2 input file written by vinculo").splitlines()
    out.append(_header("LINE TYPES"))
    out += _table(
        ["TypeName", "Diam", "Mass/m", "EA", "BA/-zeta", "EI", "Cd", "Ca", "CdAx", "CaAx"],
        ["(name)", "(m)", "(kg/m)", "(N)", "(N-s/-)", "(N-m^2)", "(-)", "(-)", "(-)", "(-)"],
        [[t.name, _g(t.diameter), _g(t.mass_per_length), _ea_text(t, curve_paths),
          *map(_g, (t.ba, t.ei, t.cd, t.ca, t.cdax, t.caax))]
         for t in model.line_types.values()],
    )
    if model.bodies:
        out.append(_header("BODIES"))
        out += _table(
            list(_BODY_COLUMNS),
            ["(#)", "(-)", "(m)", "(m)", "(m)", "(deg)", "(deg)", "(deg)", "(kg)", "(m)",
             "(kg-m^2)", "(m^3)", "(m^2)", "(-)"],
            [[str(b.id), _ATTACHMENT_WORDS[b.attachment], *map(_g, b.position),
              *map(_g, b.rotation), *b.properties] for b in model.bodies],
        )
    out.append(_header("POINTS"))
    out += _table(
        ["ID", "Attachment", "X", "Y", "Z", "Mass", "Volume", "CdA", "Ca"],
        ["(#)", "(-)", "(m)", "(m)", "(m)", "(kg)", "(m^3)", "(m^2)", "(-)"],
        [[str(p.id),
          _ATTACHMENT_WORDS[p.attachment] if p.body is None else f"Body{p.body}",
          *map(_g, p.position if p.relative is None else p.relative),
          *map(_g, (p.mass, p.volume, p.cda, p.ca))] for p in model.points],
    )
    out.append(_header("LINES"))
    out += _table(
        ["ID", "LineType", "AttachA", "AttachB", "UnstrLen", "NumSegs", "LineOutputs"],
        ["(#)", "(name)", "(#)", "(#)", "(m)", "(-)", "(-)"],
        [[str(ln.id), ln.line_type, str(ln.attach_a), str(ln.attach_b),
          _g(ln.unstretched_length), str(ln.segments), ln.outputs or "-"]
         for ln in model.lines],
    )
    out.append(_header("OPTIONS"))
    o = model.options
    defaults = FileOptions()
    option_lines: list[tuple[str, str, str]] = []
    for key, text in o.settings:
        option_lines.append((text, key, ""))
    named = [
        ("time_step", "dtM", "time step (s)"),
        ("gravity", "g", "gravitational acceleration (m/s^2)"),
        ("density", "WtrDnsty", "water density (kg/m^3)"),
        ("depth", "WtrDpth", "water depth (m)"),
        ("kbot", "kBot", "seabed stiffness (Pa/m)"),
        ("cbot", "cBot", "seabed damping (Pa-s/m)"),
        ("friction", "FrictionCoefficient", "seabed friction coefficient (-)"),
        ("axial_friction", "MU_KA", "axial seabed friction coefficient (-)"),
        ("friction_damping", "FricDamp", "friction damping (s/m)"),
        ("static_dynamic_scale", "StatDynFricScale", "static over dynamic friction (-)"),
        ("wave_ramp", "waveKin_rampT", "the waves' ramp time (s)"),
    ]
    for attr, key, description in named:
        value = getattr(o, attr)
        if value is None or (attr not in ("depth", "gravity", "density")
                             and value == getattr(defaults, attr)):
            continue
        option_lines.append((_g(value), key, description))
    if o.seafloor is not None:
        floor = seafloor_path if seafloor_path is not None else (
            o.seafloor.path if o.seafloor.layout == "C" else None)
        if floor is None:
            raise InvalidInputError(
                "the model's seafloor was built in code and has no file: give seafloor_path "
                "(write_moordyn writes the grid beside the file)", name="seafloor_path",
                value=None)
        option_lines.append((str(Path(floor).resolve()) if seafloor_path is None else str(floor),
                             "SeafloorFile", "3D seafloor file path"))
    if o.current is not None:
        option_lines.append(("1", "Currents", f"steady current from {PROFILE_FILE}"))
    if o.waves is not None:
        option_lines.append(("7", "WaveKin", f"waves summed from {WAVE_FILE}"))
    width_v = max((len(v) for v, _, _ in option_lines), default=1)
    width_k = max((len(k) for _, k, _ in option_lines), default=1)
    out += [f"{v.ljust(width_v)}  {k.ljust(width_k)}  {d}".rstrip() for v, k, d in option_lines]
    if model.outputs:
        out.append(_header("OUTPUTS"))
        out += list(model.outputs)
    out.append(_header("need this line"))
    return "\n".join(out) + "\n"


def write_moordyn(model: MoorDynFile, path: str | Path) -> Path:
    """Write ``model`` as a MoorDyn v2 input file (which MoorDyn itself reads).

    Arguments:
        model: the model.
        path: the file to write (replaced if it exists).

    Returns:
        The path written.

    Raises:
        MooringFileError: when the file cannot be written.
    """
    path = Path(path)
    floor = model.options.seafloor
    seafloor_path = None
    if floor is not None and (floor.path is None or floor.layout != "C"):
        # A grid built in code: written beside the file, which names it by its file name
        # (MoorDyn looks in the working directory, vinculo beside the file first).
        seafloor_path = floor.write(path.with_name(path.stem + "_seafloor.txt")).name
    # Stiffness curves: written beside the file, where MoorDyn looks for them (it prefixes
    # the input file's folder to the name given, even to an absolute path).
    curve_paths = {t.name: t.ea_curve.write(path.with_name(f"{path.stem}_{t.name}_ea.txt")).name
                   for t in model.line_types.values() if t.ea_curve is not None}
    try:
        if model.options.current is not None:
            # MoorDyn reads the profile of Currents 1 beside the input file.
            model.options.current.write(path.with_name(PROFILE_FILE))
        if model.options.waves is not None:
            model.options.waves.write(path.with_name(WAVE_FILE))
        path.write_text(format_moordyn(model, seafloor_path, curve_paths), encoding="utf-8")
    except OSError as exc:
        raise MooringFileError(f"cannot write the MoorDyn file {str(path)!r}: {exc.strerror}",
                               file=str(path), line=None, field=None, value=None) from None
    return path
