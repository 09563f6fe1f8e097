"""The two make targets: the release build shows its progress, and the Rust tests reuse its
compiled dependencies instead of compiling them a second time.

Cargo reuses a compiled crate only when profile and feature set are the same. The reference for
the feature sets is cargo itself (``cargo tree``, offline, from Cargo.lock): the features every
dependency of the release build gets must be those it gets in the test build the Makefile runs.
"""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _recipe_line(target: str, word: str) -> list[str]:
    """The words of the line of ``target``'s recipe in the Makefile that contains ``word``."""
    text = (ROOT / "Makefile").read_text()
    recipe = re.search(rf"^{re.escape(target)}:.*\n((?:\t.*\n)+)", text, re.MULTILINE)
    assert recipe, f"no recipe for {target}"
    lines = [line.strip() for line in recipe.group(1).splitlines() if word in line]
    assert len(lines) == 1, (target, word, lines)
    return shlex.split(lines[0])


def test_the_release_build_shows_progress_and_keeps_pip_quiet():
    build = _recipe_line("build", "maturin")
    assert "develop" in build and "--release" in build
    assert "--quiet" not in build and "-q" not in build  # cargo's progress is shown
    assert "$(QUIET_PIP)" in build  # pip's "Requirement already satisfied" lines are not
    assert "PIP_QUIET=1" in (ROOT / "Makefile").read_text()
    assert "make test" in (ROOT / ".ci" / "run").read_text().splitlines()[-1]


def test_clippy_shares_the_release_builds_pyo3_configuration():
    # clippy in the release profile reuses the build's proc-macros and build scripts; with the
    # environment maturin gives pyo3 (its configuration file above all) it does not rerun pyo3's
    # build scripts, which made the next build recompile pyo3 and the binding crate.
    text = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^clippy:.*\n((?:\t.*\n)+)", text, re.MULTILINE).group(1)
    assert "cargo clippy" in recipe and "--release" in recipe and "-D warnings" in recipe
    for variable in ("PYO3_CONFIG_FILE", "PYO3_PYTHON", "PYO3_ENVIRONMENT_SIGNATURE",
                     "PYO3_BUILD_EXTENSION_MODULE"):
        assert variable in recipe, variable


def _features(arguments: list[str]) -> dict[str, str]:
    """``{package: features}`` of a cargo build, from ``cargo tree``."""
    result = subprocess.run(
        ["cargo", "tree", "--offline", "--locked", "--prefix", "none", "-f", "{p}|{f}",
         *arguments],
        cwd=ROOT, capture_output=True, text=True, check=False,
    )
    if result.returncode != 0:
        pytest.skip(f"cargo tree cannot run offline here: {result.stderr.strip()[:200]}")
    packages = {}
    for line in result.stdout.splitlines():
        name, _, features = line.removesuffix(" (*)").partition("|")
        if not name.strip():
            continue  # the blank line between the trees of two selected packages
        packages[name.split()[0]] = features.strip()  # "faer v0.24.4" -> "faer"
    return packages


@pytest.mark.skipif(shutil.which("cargo") is None, reason="needs cargo")
def test_rust_tests_reuse_the_release_builds_dependencies():
    build = _recipe_line("build", "maturin")
    tests = _recipe_line("rust-test", "cargo test")
    # Same profile: maturin's --release and the tests' --release.
    assert "--release" in build and "--release" in tests
    selected = [tests[k + 1] for k, word in enumerate(tests) if word == "-p"]
    assert "vinculo-python" in selected  # the crate maturin builds: its features count
    # What the release build compiles (maturin builds the binding crate, normal and build
    # dependencies) and what the tests compile (the selected crates, dev-dependencies too).
    release = _features(["-p", "vinculo-python", "-e", "normal,build"])
    test = _features([arg for p in selected for arg in ("-p", p)] + ["-e", "normal,build,dev"])
    differing = {name for name, features in release.items() if test.get(name) != features}
    # Only `either` differs: criterion, a dev-dependency of the benchmarks, turns on its
    # use_std, which recompiles either and rayon (seconds); faer and the rest are shared. A
    # plain `cargo test -p vinculo` differs in num-traits and num-complex too, so every faer
    # crate compiled twice.
    assert differing <= {"either"}, sorted(differing)
