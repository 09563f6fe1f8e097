"""``vinculo mooring``: bad arguments and bad input files stop the command with exit code 2
and a message naming the file, the line (or row) and the field, before anything is computed or
written."""

from pathlib import Path

import pytest

from vinculo import cli

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
TAUT = DATA / "taut_line.txt"


@pytest.mark.parametrize(
    "arguments",
    [
        ["mooring"],
        ["mooring", "statics"],
        ["mooring", "statics", "no/such/file.txt"],
        ["mooring", "run", str(TAUT)],  # --t-end is required
        ["mooring", "run", str(TAUT), "--t-end", "-1"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--dt", "0"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--motion", "no/such/motion.csv"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--tolerance", "0"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--tolerance", "1"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--tolerance", "nan"],
        ["mooring", "run", str(TAUT), "--t-end", "10", "--tolerance", "tight"],
    ],
)
def test_bad_arguments_exit_with_code_2(arguments, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(arguments)
    assert info.value.code == 2
    assert "usage: vinculo mooring" in capsys.readouterr().err


@pytest.mark.parametrize("action", [["statics"], ["run", "--t-end", "1"]])
def test_a_bad_mooring_file_names_file_line_and_field(tmp_path, capsys, action):
    bad = tmp_path / "bad.txt"
    bad.write_text(TAUT.read_text().replace("1.0e7  -1.0", "1.0e7  -1.0x", 1))
    output = tmp_path / "out"
    code = cli.main(["mooring", action[0], str(bad), *action[1:], "--output", str(output)])
    assert code == 2
    err = capsys.readouterr().err
    assert f"{bad}, line 7: BA/-zeta: '-1.0x' is not a number" in err
    assert not output.exists()  # nothing written


def _motion(path: Path, rows: list[str], header: str = "time,x1,y1,z1") -> Path:
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


@pytest.mark.parametrize(
    ("header", "rows", "words"),
    [
        ("time,x1,y1,z1", ["0,0,0,-5", "1,0.1,0,-5", "2,0.2,zero,-5"],
         "row 4, column 'y1': 'zero' is not a number"),
        ("time,x1,y1,z1", ["0,0,0,-5", "1,0.1,0,-5", "1,0.2,0,-5"], "row 4: the times must"),
        ("time,x1,y1", ["0,0,0", "1,0.1,0"], "1 + 3 n columns"),
        ("time,x1,y1,z1,x2,y2,z2", ["0,0,0,-5,1,0,-5", "20,0,0,-5,1,0,-5"],
         "moves 2 points but"),
        ("time,x1,y1,z1", ["0,0,0,-5", "0.5,0,0,-5"], "covers t = 0 to 0.5 s"),
    ],
)
def test_a_bad_motion_file_is_named(tmp_path, capsys, header, rows, words):
    motion = _motion(tmp_path / "motion.csv", rows, header)
    code = cli.main(["mooring", "run", str(TAUT), "--motion", str(motion), "--t-end", "1",
                     "--output", str(tmp_path / "out")])
    assert code == 2
    err = capsys.readouterr().err
    assert words in err
    assert "error:" in err


@pytest.mark.parametrize("every", ["0.03", "0", "-0.1"])
def test_an_output_interval_that_is_not_a_whole_number_of_steps_is_refused(every, tmp_path,
                                                                           capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["mooring", "run", str(TAUT), "--t-end", "1", "--dt", "0.02",
                  "--output-every", every, "--output", str(tmp_path / "out")])
    assert info.value.code == 2
    assert "--output-every" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing written


def test_a_reader_that_closes_the_output_ends_the_command_without_a_traceback(tmp_path):
    # `vinculo mooring statics FILE | head -c 0`: the printing fails with a broken pipe, which
    # ends the command with the shell's code for it (128 + SIGPIPE) and no traceback.
    import subprocess
    import sys

    command = [sys.executable, "-m", "vinculo.cli", "mooring", "statics", str(TAUT),
               "--output", str(tmp_path)]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as child:
        child.stdout.close()
        err = child.stderr.read().decode()
        code = child.wait()
    assert code == 141, err
    assert "Traceback" not in err
