"""Fixtures of the mooring tests."""

import sys

import pytest


@pytest.fixture
def line_api(monkeypatch):
    """The line and statics modules of the mooring contract: the real ones when this tree has
    them, else the catenary stand-in of ``stand_in_line.py`` (returns "real" or "stand-in")."""
    try:
        import vinculo.mooring.line
        import vinculo.mooring.statics  # noqa: F401
    except ImportError:
        import stand_in_line

        monkeypatch.setitem(sys.modules, "vinculo.mooring.line", stand_in_line)
        monkeypatch.setitem(sys.modules, "vinculo.mooring.statics", stand_in_line)
        return "stand-in"
    return "real"
