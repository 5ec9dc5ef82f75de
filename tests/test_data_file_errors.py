"""GRACE data files: every malformed file is named with its line (issue 36, item 2).

The vendored files read as before (bitwise: the reader's arithmetic is unchanged;
checked against a copy of main during development). Each malformed variant
below is refused with an InputError naming the file and, for content, the line.
"""

import gzip
import re

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers.grace2010.dataset import read_orbit_file, read_range_file

GOOD = ("27/7/2010,00:00:00,2046.25,270.77,6513.38,-72393.98,-6729.94,23093.89\n"
        "27/7/2010,00:00:10,1973.72,264.07,6536.07,-72652.59,-6657.28,22280.33\n")


def test_good_file_reads_with_units_converted(tmp_path):
    f = tmp_path / "orbit.csv"
    f.write_text(GOOD)
    t, r, v = read_orbit_file(f)
    np.testing.assert_array_equal(t, [0.0, 10.0])                   # seconds since 2010-07-27 00:00
    np.testing.assert_allclose(r[0], [2046.25e3, 270.77e3, 6513.38e3], rtol=1e-15)  # km → m
    np.testing.assert_allclose(v[0], [-7239.398, -672.994, 2309.389], rtol=1e-15)    # dm/s → m/s


@pytest.mark.parametrize("content, words", [
    (GOOD.replace("2046.25", "nan"), r"line 1 has NaN or inf"),
    (GOOD.replace("2046.25", "2046,25"), r"line 1 has 9 fields"),
    (GOOD.replace("1973.72", "1973.7x"), r"line 2: could not convert"),
    (GOOD.replace("27/7/2010,00:00:10", "31/2/2010,00:00:10"), r"line 2: date '31/2/2010'"),
    (GOOD.replace("00:00:10", "00:00:00"), r"line 2: time .* not after"),
    (GOOD.replace("00:00:10", "25:00:10"), r"line 2: .*out of range"),
    ("", "no data lines"),
    ("\n\n", "no data lines"),
])
def test_malformed_orbit_files_name_the_line(tmp_path, content, words):
    f = tmp_path / "orbit.csv"
    f.write_text(content)
    with pytest.raises(InputError, match=words) as info:
        read_orbit_file(f)
    assert "orbit.csv" in str(info.value)


def test_encoding_and_gzip_errors_name_the_file(tmp_path):
    latin = tmp_path / "latin.csv"
    latin.write_bytes((GOOD + "# décalage\n").encode("latin-1"))
    with pytest.raises(InputError, match=r"latin\.csv: line 3: byte 0xe9 is not ASCII"):
        read_orbit_file(latin)
    whole = gzip.compress(GOOD.encode())
    for name, data in (("cut.csv.gz", whole[:-12]), ("fake.csv.gz", GOOD.encode()), ("empty.csv.gz", b"")):
        f = tmp_path / name
        f.write_bytes(data)
        with pytest.raises(InputError, match=re.escape(name) + ": (not a complete gzip file|no data)"):
            read_range_file(f) if name == "empty.csv.gz" else read_orbit_file(f)
