"""Every public name of the vinculo package has a docstring (the API reference is built from them).

The package is read statically by griffe, the reader the documentation site uses, so the compiled
module's classes and functions are checked through its stub ``python/vinculo/_core.pyi``, exactly
as the API pages show them. Public names are: everything in ``vinculo.__all__``; in every public
submodule (no leading underscore anywhere in its path), the names of its ``__all__``, or, without
one, its functions and classes that do not start with an underscore; and the public methods and
properties of every such class. A module-level constant may carry its docstring as a string after
the assignment or as a ``#:`` comment above it.
"""

import re
from pathlib import Path

import pytest

griffe = pytest.importorskip("griffe")

ROOT = Path(__file__).resolve().parent.parent
PYTHON = ROOT / "python"


def _package():
    return griffe.load(
        "vinculo", search_paths=[str(PYTHON)], allow_inspection=False, resolve_aliases=True
    )


def _public_modules(module):
    yield module
    for name, member in module.members.items():
        if member.is_alias or not member.is_module or name.startswith("_"):
            continue
        yield from _public_modules(member)


def _has_comment_docstring(obj) -> bool:
    """A ``#:`` comment on the line above an attribute (Sphinx style)."""
    if obj.lineno is None or obj.filepath is None:
        return False
    lines = Path(obj.filepath).read_text().splitlines()
    return obj.lineno >= 2 and lines[obj.lineno - 2].strip().startswith("#:")


def _documented(obj) -> bool:
    if obj.docstring is not None and obj.docstring.value.strip():
        return True
    return obj.is_attribute and _has_comment_docstring(obj)


def _public_names(module):
    """(qualified name, object) of every public name a module offers."""
    if module.exports is not None:
        names = [str(name) for name in module.exports]
    else:
        names = [
            name
            for name, member in module.members.items()
            if not name.startswith("_")
            and not member.is_alias
            and (member.is_function or member.is_class)
        ]
    for name in names:
        obj = module[name]
        target = obj.final_target if obj.is_alias else obj
        yield f"{module.path}.{name}", target
        if target.is_class:
            for member_name, member in target.members.items():
                if member_name.startswith("_") or member.is_alias:
                    continue
                if member.is_function or "property" in member.labels:
                    yield f"{module.path}.{name}.{member_name}", member


def _undocumented():
    package = _package()
    missing = set()
    for module in _public_modules(package):
        if not _documented(module):
            missing.add(module.path)
        for path, obj in _public_names(module):
            if not _documented(obj):
                missing.add(path)
    return sorted(missing)


def test_public_names_are_found():
    # The check must see the package as the site does: the compiled classes through the stub,
    # the submodules, and the class members (a sanity check on the walk, not on docstrings).
    package = _package()
    names = {path for module in _public_modules(package) for path, _ in _public_names(module)}
    assert "vinculo.System" in names
    assert "vinculo.System.add_distance" in names  # from python/vinculo/_core.pyi
    assert "vinculo.simulate" in names
    assert "vinculo.buoy.run_parameter_study" in names
    assert "vinculo.io.save_netcdf" in names
    assert len(names) > 150


def test_every_public_name_has_a_docstring():
    missing = _undocumented()
    assert not missing, "public names without a docstring:\n  " + "\n  ".join(missing)


def test_every_public_module_has_an_api_page():
    # The API reference is a set of `::: module` directives in docs/reference/*.md (and the one
    # the build adds to the generated command-line page); a public module missing from them would
    # be missing from the site.
    pages = sorted((ROOT / "docs" / "reference").glob("*.md"))
    sources = [*pages, ROOT / "tools" / "docs_hooks.py"]
    documented = {
        match.group(1)
        for source in sources
        for match in re.finditer(r"^\s*\"?::: ([\w.]+)", source.read_text(), re.MULTILINE)
    }
    modules = {module.path for module in _public_modules(_package())}
    assert not modules - documented, f"public modules without an API page: {modules - documented}"
