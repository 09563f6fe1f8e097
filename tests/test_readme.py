"""The README names what exists: every dotted ``vinculo.`` name it quotes can be imported; and
every column of ``sweep.csv`` is explained in the buoy study's guide page."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

from vinculo.buoy import BuoyCase, SweepSettings
from vinculo.buoy.report import _write_sweep
from vinculo.buoy.study import StudyResult

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BUOY_GUIDE = ROOT / "docs" / "guide" / "buoy-study.md"


def _resolve(dotted: str) -> object:
    """The object a dotted name refers to: the longest importable module, then attributes."""
    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        try:
            target = importlib.import_module(".".join(parts[:split]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[split:]:
            target = getattr(target, attribute)
        return target
    raise ModuleNotFoundError(dotted)


def test_every_dotted_vinculo_name_in_the_readme_exists():
    # Before, the README sent users to vinculo.buoy.run_study and run_particle_model, which
    # lived only in submodules. The reference is Python's own import system.
    text = README.read_text()
    names = set(re.findall(r"`(vinculo(?:\.[A-Za-z_]\w*)+)", text))
    assert "vinculo.buoy.run_study" in names and "vinculo.buoy.run_particle_model" in names
    missing = []
    for name in sorted(names):
        try:
            _resolve(name)
        except (ImportError, AttributeError):
            missing.append(name)
    assert missing == []


def test_every_sweep_csv_column_is_explained_in_the_guide(tmp_path):
    # The header as the report writes it (an empty study); each column must be a row of the
    # guide's table (settling and residual_rms were explained nowhere).
    path = tmp_path / "sweep.csv"
    _write_sweep(StudyResult(BuoyCase(), SweepSettings(), []), None, path)
    header = path.read_text().splitlines()[0].split(",")
    text = BUOY_GUIDE.read_text()
    table = "\n".join(line for line in text.splitlines() if line.startswith("| `"))
    undocumented = [c for c in header if f"`{c}`" not in table]
    assert undocumented == []
