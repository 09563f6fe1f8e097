"""The README's links into the repository point at files that exist.

The documentation site's own links are checked by its strict build (mkdocs.yml, ``validation:``);
the README is read on its own (on a forge, or in a clone), outside that build, so its relative
links and images are checked here.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def relative_targets(text: str) -> list[str]:
    """The targets of Markdown links and images that are paths in the repository."""
    targets = [match.group(1).split("#")[0] for match in LINK.finditer(text)]
    return [t for t in targets if t and "://" not in t and not t.startswith("mailto:")]


def test_the_link_pattern_finds_links_and_images():
    # A check of the check: both kinds are found, anchors dropped, web addresses left out.
    text = "See [a](docs/a.md#x), ![b](docs/b.png) and [c](https://example.org/c)."
    assert relative_targets(text) == ["docs/a.md", "docs/b.png"]


def test_readme_links_point_at_files():
    missing = [t for t in relative_targets((ROOT / "README.md").read_text())
               if not (ROOT / t).exists()]
    assert not missing, f"README links to missing files: {missing}"


CITED = re.compile(r"\bdocs/[A-Za-z0-9_./-]+\.md\b")


def test_every_document_the_code_cites_is_in_the_repository():
    # Derivations cited from code, tests and examples (e.g. "docs/theory/formulation.md") must
    # be pages of this repository, which a reader of the project can open.
    sources = [
        path
        for folder in ("crates", "python", "tests", "examples", "tools")
        for path in (ROOT / folder).rglob("*")
        if path.suffix in {".rs", ".py", ".pyi"} and path.resolve() != Path(__file__).resolve()
    ]
    assert len(sources) > 50
    missing = sorted(
        {
            f"{path.relative_to(ROOT)}: {cited}"
            for path in sources
            for cited in CITED.findall(path.read_text(encoding="utf-8", errors="replace"))
            if not (ROOT / cited).exists()
        }
    )
    assert not missing, f"cited documents missing from the repository: {missing}"
