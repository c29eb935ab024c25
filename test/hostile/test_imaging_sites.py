"""Hostile CSV target lists: each bad row refused with its line and column, never a crash or a
silent default."""
from __future__ import annotations

import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.imaging import sites
from att_sim.models.config_files import ConfigFileError

HEADER = "name,latitude_deg,longitude_deg,priority\n"


def refused(tmp_path, content: bytes | str) -> str:
    path = tmp_path / "targets.csv"
    (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
    with pytest.raises(ConfigFileError) as err:
        sites.from_spec(str(path))
    assert err.value.code == ErrorCode.INVALID_CONFIG
    return err.value.message.replace(str(path), "F")


def test_a_missing_column_is_named(tmp_path):
    assert refused(tmp_path, "name,latitude_deg,priority\na,1,1\n") == \
        "F:1: longitude_deg: expected the columns name, latitude_deg, longitude_deg, priority; found no column(s) " \
        "longitude_deg"


def test_an_unknown_column_is_named(tmp_path):
    assert "F:1: lat: expected a column of name, latitude_deg" in refused(tmp_path, "name,lat,longitude_deg,priority\n")


@pytest.mark.parametrize("row, expected", [
    ("a,nan,1,1", "F:2: latitude_deg: expected less than or equal to 90; found nan"),
    ("a,91,1,1", "F:2: latitude_deg: expected less than or equal to 90; found 91.0"),
    ("a,-90.5,1,1", "F:2: latitude_deg: expected greater than or equal to -90; found -90.5"),
    ("a,1,inf,1", "F:2: longitude_deg: expected less than or equal to 360; found inf"),
    ("a,1,1,north", "F:2: priority: expected a valid number; found 'north'"),
    ("a,1,1,", "F:2: priority: expected a valid number; found ''"),
    ("a,1,1,-1", "F:2: priority: expected greater than or equal to 0; found -1.0"),
    ("a,1,1", "F:2: (file): expected 4 cells (the header's); found 3 cells"),
    (",1,1,1", "F:2: name: expected String should have at least 1 character; found ''"),
])
def test_a_bad_value_is_refused_on_its_line_and_column(tmp_path, row, expected):
    message = refused(tmp_path, HEADER + row + "\n")
    assert message == expected, message


def test_half_a_strip_is_refused(tmp_path):
    message = refused(tmp_path, "name,latitude_deg,longitude_deg,priority,end_latitude_deg,end_longitude_deg\n"
                                "a,1,1,1,2,\n")
    assert message.startswith("F:2: (file): expected both end_latitude_deg and end_longitude_deg"), message


def test_a_name_given_twice_is_refused_naming_both_lines(tmp_path):
    assert refused(tmp_path, HEADER + "a,1,1,1\nb,2,2,1\na,3,3,1\n") == \
        "F:4: name: expected distinct names; found 'a', also on line 2"


def test_every_bad_row_is_reported(tmp_path):
    message = refused(tmp_path, HEADER + "a,100,1,1\nb,1,1,x\nc,1,1,1\n")
    first, second = message.splitlines()
    assert first.startswith("F:2: latitude_deg") and second.startswith("F:3: priority")


def test_a_file_that_is_not_utf8_is_refused(tmp_path):
    assert refused(tmp_path, HEADER.encode() + b"caf\xe9,1,1,1\n") == \
        "F:2: (file): expected UTF-8 text; found the byte 0xe9 at offset 44"


def test_a_huge_file_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "targets.csv"
    with open(path, "wb") as fh:
        fh.truncate(sites.MAX_CSV_BYTES + 1)
    with pytest.raises(ConfigFileError) as err:
        sites.read_csv(path)
    assert f"expected a file of at most {sites.MAX_CSV_BYTES} bytes" in err.value.message


def test_too_many_rows_are_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(sites, "MAX_SITES", 3)
    assert refused(tmp_path, HEADER + "".join(f"s{k},1,1,1\n" for k in range(5))) == \
        "F:5: (file): expected at most 3 rows; found more"


@pytest.mark.parametrize("content", ["", "\n\n", HEADER, "\x00" + HEADER, 'name,"latitude_deg\n'])
def test_an_empty_or_broken_file_is_refused(tmp_path, content):
    assert refused(tmp_path, content).startswith("F")


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(ConfigFileError, match="expected a readable CSV file"):
        sites.from_spec(str(tmp_path / "none.csv"))
