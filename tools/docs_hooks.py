"""MkDocs hooks of the documentation site (mkdocs.yml, ``hooks:``): the pages made at build time.

- ``reference/cli.md``: every command and option of the ``vinculo`` command line, read from the
  argparse parsers of :mod:`vinculo.cli`, so that the reference cannot drift from the program.
- ``gallery.md`` and ``gallery/*.png``: every script in ``examples/`` is run (in parallel, with
  this interpreter, warnings as errors); its figure and printed output go on the gallery page, and
  the tutorials show the same figures. A script that fails fails the build.

Both need the compiled extension (``make build``), because they import or run ``vinculo``.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

# Arguments of each example in the gallery run; {plot} is the figure, {work} a scratch folder.
# Scripts not listed get ["--plot", "{plot}"].
EXAMPLE_ARGUMENTS: dict[str, list[str]] = {
    "result_files.py": ["{work}/files", "--plot", "{plot}"],
}

# Longest a single example may run in the build (s).
EXAMPLE_TIMEOUT = 120.0

_scratch: list[Path] = []
_outputs: dict[str, str] = {}

# A page may show what an example printed in this build: this comment on a line of its own
# becomes a text block with the output of examples/NAME.py.
OUTPUT_MARKER = re.compile(r"^<!-- example-output: ([\w.-]+) -->$", re.MULTILINE)


def on_files(files, config):
    """Add the generated pages and figures to the site's files.

    Arguments:
        files: the files MkDocs found in ``docs/``.
        config: the site's configuration.

    Returns:
        The files, with ``reference/cli.md``, ``gallery.md`` and ``gallery/*.png`` added.

    Raises:
        PluginError: when ``vinculo`` cannot be imported (build it first) or an example fails.
    """
    sys.path.insert(0, str(ROOT / "python"))
    try:
        from vinculo import cli
    except ImportError as exc:  # the compiled module is missing
        raise PluginError(
            f"the documentation needs the compiled vinculo module ({exc}); run `make build` first"
        ) from exc
    files.append(File.generated(config, "reference/cli.md", content=cli_reference(cli)))

    work = Path(tempfile.mkdtemp(prefix="vinculo-docs-"))
    _scratch.append(work)
    runs = run_examples(work)
    _outputs.clear()
    _outputs.update({run.script.name: run.output for run in runs})
    for run in runs:
        figure = f"gallery/{run.figure.name}"
        files.append(File.generated(config, figure, abs_src_path=str(run.figure)))
    files.append(File.generated(config, "gallery.md", content=gallery_page(runs)))
    return files


def on_page_markdown(markdown, page, config, files):
    """Put each example's output where a page asks for it with an ``example-output`` comment.

    Arguments:
        markdown: the page's Markdown text.
        page: the page.
        config: the site's configuration.
        files: the site's files.

    Returns:
        The Markdown text with the outputs in place.

    Raises:
        PluginError: a marker names a script that is not in ``examples/``.
    """

    def output(match: re.Match) -> str:
        name = match.group(1)
        if name not in _outputs:
            raise PluginError(f"{page.file.src_uri} asks for the output of {name}, "
                              f"which is not a script of examples/")
        return "```text\n" + _shown(_outputs[name]) + "\n```"

    return OUTPUT_MARKER.sub(output, markdown)


# Sphinx roles in docstrings (:class:`X`, :func:`~a.b`) reach the HTML as ":class:<code>X</code>".
SPHINX_ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):<code>(~?)([\w.]+)</code>")
_objects: dict[str, str | None] = {}
LITERAL_MARKER = re.compile(r"(?<=\w)::(</p>)")


def _object_index() -> dict[str, str | None]:
    """Every dotted suffix of every object's path in the package -> that path (None: ambiguous)."""
    if not _objects:
        import griffe

        package = griffe.load("vinculo", search_paths=[str(ROOT / "python")],
                              allow_inspection=False)
        paths: set[str] = set()

        def walk(obj) -> None:
            paths.add(obj.path)
            for member in obj.members.values():
                if not member.is_alias:
                    walk(member)

        walk(package)
        for path in paths:
            parts = path.split(".")
            for k in range(len(parts)):
                suffix = ".".join(parts[k:])
                _objects[suffix] = path if _objects.get(suffix, path) == path else None
    return _objects


def on_page_content(html, page, config, files):
    """Turn the Sphinx roles of docstrings into cross-references (or plain code), and "::" to ":".

    Arguments:
        html: the page's HTML.
        page: the page.
        config: the site's configuration.
        files: the site's files.

    Returns:
        The HTML with ``:class:`X``` and the like replaced by links to X's documentation where X
        names one object of the package, else by ``X`` as code.
    """
    # A reST literal-block marker ("reads::") ends a paragraph before a code block: one colon.
    html = LITERAL_MARKER.sub(r":\1", html)
    if ":<code>" not in html:
        return html
    index = _object_index()

    def reference(match: re.Match) -> str:
        tilde, target = match.groups()
        shown = target.rsplit(".", 1)[-1] if tilde else target
        path = index.get(target)
        if path is None:
            return f"<code>{shown}</code>"
        return f'<autoref identifier="{path}" optional><code>{shown}</code></autoref>'

    return SPHINX_ROLE.sub(reference, html)


def _shown(output: str) -> str:
    """An example's output as shown on a page: without the line naming its scratch figure."""
    lines = [line for line in output.rstrip().splitlines() if not line.startswith("plot: ")]
    return "\n".join(lines)


def on_post_build(config):
    """Remove the scratch folders of the example runs.

    Arguments:
        config: the site's configuration.
    """
    while _scratch:
        shutil.rmtree(_scratch.pop(), ignore_errors=True)


# ---------------------------------------------------------------------------------------------
# The command-line reference


def cli_reference(cli) -> str:
    """The Markdown page of every command and option of the ``vinculo`` command line.

    Arguments:
        cli: the module :mod:`vinculo.cli`.

    Returns:
        The page's Markdown text.
    """
    main = cli._build_parser()
    commands = _subcommands(main)
    lines = [
        "# Command line",
        "",
        "<!-- Generated at build time from the argparse parsers of python/vinculo/cli.py -->",
        "",
        "The `vinculo` program (also `python -m vinculo`) has three commands, `demo`, `buoy` "
        "and `mooring`; `buoy` has two more, `buoy sweep` and `buoy calibrate`, and `mooring` "
        "has `mooring statics` and `mooring run`. "
        "This page is generated from the program's own parsers when the site is built, so it "
        "lists exactly the options the program accepts; `vinculo COMMAND --help` prints the same. "
        "Lengths are in metres, times in seconds, frequencies in hertz and angles in degrees "
        "unless an option says otherwise. "
        "Exit codes: 0 on success, 1 when a simulation fails, 2 on bad arguments.",
        "",
    ]
    lines += _parser_section("vinculo", main, level=2, with_commands=True)
    for name, parser in commands.items():
        lines += _parser_section(f"vinculo {name}", parser, level=2)
        if name == "buoy":
            lines += _parser_section("vinculo buoy sweep", cli._study_parser(), level=2)
            lines += _parser_section("vinculo buoy calibrate", cli._calibrate_parser(), level=2)
        for action_name, action_parser in _subcommands(parser).items():
            lines += _parser_section(f"vinculo {name} {action_name}", action_parser, level=2)
    lines += [
        "## From Python",
        "",
        "The program is `vinculo.cli.main`; `python -m vinculo` runs it too.",
        "",
        "::: vinculo.cli",
        "    options:",
        "      show_root_heading: false",
        "      heading_level: 3",
        "",
    ]
    return "\n".join(lines) + "\n"


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _parser_section(title: str, parser, level: int, with_commands: bool = False) -> list[str]:
    hashes = "#" * level
    usage = parser.format_usage().strip().removeprefix("usage: ")
    lines = [f"{hashes} `{title}`", "", "```text", usage, "```", ""]
    if parser.description:
        lines += [parser.description, ""]
    formatter = parser._get_formatter()
    units = _parameter_units()
    descriptions = _parameter_descriptions()
    for group in parser._action_groups:
        rows = []
        with_units = any(_unit(action, units) for action in group._group_actions)
        for action in group._group_actions:
            if isinstance(action, argparse._SubParsersAction):
                if with_commands:
                    rows += [
                        f"| `{choice.dest}` | |{' |' if with_units else ''} | "
                        f"{_cell(choice.help or '')} |"
                        for choice in action._choices_actions
                    ]
                continue
            if action.help == argparse.SUPPRESS:
                continue
            name = ", ".join(f"`{s}`" for s in action.option_strings) or f"`{action.dest}`"
            argument = _argument(action)
            default = _default(action)
            text = formatter._expand_help(action) if action.help else ""
            if action.dest in descriptions:  # a case or sweep parameter: say what it is
                described = descriptions[action.dest]
                if not default and text.startswith("default: ") and ";" not in text:
                    default, text = f"`{text.removeprefix('default: ')}`", ""
                text = f"{described} ({text})" if text else described
            unit = f" {_unit(action, units)} |" if with_units else ""
            rows.append(f"| {name} | {argument} |{unit} {default} | {_cell(text)} |")
        if not rows:
            continue
        commands = any(isinstance(a, argparse._SubParsersAction) for a in group._group_actions)
        heading = "commands" if commands else (group.title or "arguments")
        heading = heading[0].upper() + heading[1:]
        lines += [
            f"{hashes}# {heading} of `{title}`" if heading else "",
            "",
            "| option | value | unit | default | meaning |" if with_units
            else "| option | value | default | meaning (units) |",
            "| --- | --- | --- | --- | --- |" if with_units else "| --- | --- | --- | --- |",
            *rows,
            "",
        ]
    return lines


def _parameter_descriptions() -> dict[str, str]:
    """The description of each buoy case and sweep parameter, from the Arguments sections of the
    docstrings of ``BuoyCase`` and ``SweepSettings`` (keys ``case__NAME`` and ``sweep__NAME``, as
    the command line's option destinations)."""
    import griffe

    module = griffe.load("vinculo.buoy.case", search_paths=[str(ROOT / "python")],
                         allow_inspection=False)
    descriptions = {}
    for cls, table in (("BuoyCase", "case"), ("SweepSettings", "sweep")):
        docstring = module[cls].docstring
        for section in docstring.parse("google") if docstring else []:
            if section.kind.value == "parameters":
                for parameter in section.value:
                    descriptions[f"{table}__{parameter.name}"] = parameter.description
    return descriptions


def _parameter_units() -> dict[str, str]:
    """The unit of each buoy case and sweep parameter (``vinculo.buoy.case.UNITS``, as ``--help``
    states it)."""
    from vinculo.buoy.case import UNITS

    return dict(UNITS)


def _unit(action: argparse.Action, units: dict[str, str]) -> str:
    """The unit of a case or sweep parameter option (its dest is ``case__NAME``), else ""."""
    _, _, name = action.dest.rpartition("__")
    return units.get(name, "") if "__" in action.dest else ""


def _argument(action: argparse.Action) -> str:
    if action.nargs == 0:
        return ""
    if action.choices:
        return " \\| ".join(f"`{c}`" for c in action.choices)
    metavar = action.metavar or action.dest.upper()
    return f"`{metavar}`"


def _default(action: argparse.Action) -> str:
    if action.nargs == 0 or action.default in (None, argparse.SUPPRESS, [], ""):
        return ""
    return f"`{action.default}`"


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


# ---------------------------------------------------------------------------------------------
# The gallery


class ExampleRun:
    """One example script run for the gallery.

    Arguments:
        script: the script's path.
        figure: where its figure was written.
        output: what it printed.
        seconds: its wall time (s).
    """

    def __init__(self, script: Path, figure: Path, output: str, seconds: float):
        self.script = script
        self.figure = figure
        self.output = output
        self.seconds = seconds


def run_examples(work: Path) -> list[ExampleRun]:
    """Run every script of ``examples/`` with a figure into ``work``.

    Arguments:
        work: a scratch folder for the figures and any files the scripts write.

    Returns:
        One run per script, in the order of their names.

    Raises:
        PluginError: naming the script and its error output, when a script fails or writes no
            figure.
    """
    scripts = sorted(EXAMPLES.glob("*.py"))
    workers = max(1, min(2, os.cpu_count() or 1))
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda script: _run_example(script, work), scripts))


def _run_example(script: Path, work: Path) -> ExampleRun:
    figure = work / f"{script.stem}.png"
    scratch = work / script.stem
    scratch.mkdir()
    template = EXAMPLE_ARGUMENTS.get(script.name, ["--plot", "{plot}"])
    arguments = [a.format(plot=figure, work=scratch) for a in template]
    environment = dict(os.environ, MPLBACKEND="Agg")
    environment["PYTHONPATH"] = os.pathsep.join(
        [str(ROOT / "python"), *filter(None, [os.environ.get("PYTHONPATH")])]
    )
    start = time.perf_counter()
    try:
        completed = subprocess.run(
            [sys.executable, "-W", "error", str(script), *arguments],
            capture_output=True,
            text=True,
            timeout=EXAMPLE_TIMEOUT,
            cwd=scratch,
            env=environment,
            check=False,
        )
    except subprocess.TimeoutExpired as exc:
        raise PluginError(f"example {script.name} ran longer than {EXAMPLE_TIMEOUT} s") from exc
    seconds = time.perf_counter() - start
    if completed.returncode != 0:
        raise PluginError(f"example {script.name} failed:\n{completed.stderr}")
    if not figure.is_file():
        raise PluginError(f"example {script.name} wrote no figure to {figure}")
    return ExampleRun(script, figure, completed.stdout, seconds)


def _summary(script: Path) -> tuple[str, str]:
    """The title (first docstring line) and the rest of a script's docstring."""
    import ast

    docstring = ast.get_docstring(ast.parse(script.read_text())) or script.stem
    title, _, rest = docstring.partition("\n")
    return title.strip().rstrip("."), rest.strip()


def _docstring_markdown(text: str) -> str:
    """A script's docstring as Markdown: its indented blocks (the usage lines) become code."""
    blocks = []
    for block in re.split(r"\n\s*\n", text):
        lines = block.splitlines()
        if lines and all(line.startswith("    ") for line in lines):
            blocks.append("```text\n" + "\n".join(line[4:] for line in lines) + "\n```")
        else:
            blocks.append(block)
    return "\n\n".join(blocks)


def gallery_page(runs: list[ExampleRun]) -> str:
    """The gallery page: each example's description, figure, printed output and source.

    Arguments:
        runs: the example runs.

    Returns:
        The page's Markdown text.
    """
    total = sum(run.seconds for run in runs)
    lines = [
        "# Gallery",
        "",
        "<!-- Generated at build time by tools/docs_hooks.py -->",
        "",
        "Every script in `examples/` is run when this site is built, and its figure and output "
        "below are the ones that run produced; `tests/test_examples.py` runs the same scripts "
        "and checks their numbers against independent references. Run one yourself with "
        "`python examples/NAME.py --plot NAME.png`.",
        "",
        f"This build ran {len(runs)} scripts in {total:.0f} s of wall time (summed).",
        "",
    ]
    for run in runs:
        title, rest = _summary(run.script)
        relative = run.script.relative_to(ROOT).as_posix()
        lines += [
            f"## {title}",
            "",
            f"`{relative}` ({run.seconds:.1f} s)",
            "",
            _docstring_markdown(rest),
            "",
            f"![{title}](gallery/{run.figure.name})",
            "",
            '??? example "Output"',
            "",
            "    ```text",
            *("    " + line for line in _shown(run.output).splitlines()),
            "    ```",
            "",
            '??? example "Source"',
            "",
            "    ```python",
            *("    " + line for line in run.script.read_text().rstrip().splitlines()),
            "    ```",
            "",
        ]
    return "\n".join(lines)
