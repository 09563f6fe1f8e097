"""Reading measured amplitude and phase from CSV: formats accepted, each error naming its line."""

import numpy as np
import pytest

from vinculo.buoy.data import read_measurements
from vinculo.errors import InvalidInputError


def write(tmp_path, text: str):
    path = tmp_path / "measured.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_file_without_header_with_comments_and_blank_lines(tmp_path):
    # Reference: the values written into the file.
    path = write(tmp_path, "# run 3\n\n0.5, 0.0015, 1.5\n0.6,0.0019,3.0  # windy day\n\n")
    data = read_measurements(path)
    np.testing.assert_array_equal(data.frequency, [0.5, 0.6])
    np.testing.assert_array_equal(data.amplitude, [0.0015, 0.0019])
    np.testing.assert_array_equal(data.phase_deg, [1.5, 3.0])
    assert data.motion == "absolute"
    assert data.path == str(path)


def test_header_in_any_order_with_units_and_extra_columns(tmp_path):
    # Reference: the values written into the file, reordered by the header's names.
    path = write(
        tmp_path,
        "Phase (deg), note, FREQUENCY [Hz], amplitude\n10.0, a, 0.8, 0.004\n-20.0, b, 1.2, 0.002\n",
    )
    data = read_measurements(path, motion="relative")
    np.testing.assert_array_equal(data.frequency, [0.8, 1.2])
    np.testing.assert_array_equal(data.amplitude, [0.004, 0.002])
    np.testing.assert_array_equal(data.phase_deg, [10.0, -20.0])
    assert data.motion == "relative"


def test_file_with_a_byte_order_mark(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_bytes("\ufefffrequency,amplitude,phase\n1.0,0.003,45\n".encode())
    assert read_measurements(path).phase_deg.tolist() == [45.0]


def test_missing_file_names_the_path(tmp_path):
    path = tmp_path / "absent.csv"
    with pytest.raises(InvalidInputError) as caught:
        read_measurements(path)
    assert str(path) in str(caught.value)
    assert caught.value.name == "data" and caught.value.path == str(path)
    assert caught.value.line is None


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [
        ("0.5, 0.001, 2\n0.6, 0.002\n", 2, "found 2"),
        ("# c\n0.5, 0.001, 2, 7\n", 2, "found 4"),
        ("frequency, amplitude, phase\n0.5, 0.001, 2\n\n0.7, abc, 3\n", 4, "'abc' is not a number"),
        ("0.5, 0.001, 2\n0.6, nan, 3\n", 2, "not a finite number"),
        ("0.5, 0.001, inf\n", 1, "not a finite number"),
        ("0.5, 0.001, 2\n-0.6, 0.002, 3\n", 2, "frequency -0.6"),
        ("0.0, 0.001, 2\n", 1, "frequency 0"),
        ("0.5, -0.001, 2\n", 1, "amplitude -0.001"),
        ("frequency, amplitude\n0.5, 0.001\n", 1, "lacks the column(s) phase"),
        ("0.5, x, 2\n", 1, "'x' is not a number"),
    ],
)
def test_bad_row_names_its_line(tmp_path, text, line, fragment):
    path = write(tmp_path, text)
    with pytest.raises(InvalidInputError) as caught:
        read_measurements(path)
    message = str(caught.value)
    assert f"line {line}" in message
    assert fragment in message
    assert caught.value.line == line and caught.value.name == "data"
    assert str(path) in message
    # The message quotes the offending line.
    assert text.splitlines()[line - 1].strip() in message


def test_file_without_data_rows(tmp_path):
    path = write(tmp_path, "# nothing yet\nfrequency, amplitude, phase\n\n")
    with pytest.raises(InvalidInputError, match="no data rows") as caught:
        read_measurements(path)
    assert caught.value.path == str(path)


def test_unknown_motion_is_rejected(tmp_path):
    path = write(tmp_path, "0.5, 0.001, 2\n")
    with pytest.raises(InvalidInputError) as caught:
        read_measurements(path, motion="lab")
    assert caught.value.name == "motion" and "'lab'" in str(caught.value)
