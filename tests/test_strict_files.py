"""System files and campaign specs read strictly (issue 36, item 2).

Each case is a file a user could write by mistake; the expected outcome is an
InputError naming the file and the key (or the byte and line), never a value
misread (a boolean as 0/1) or a key ignored.
"""

import pytest

from hinfnav.campaign import load_campaign
from hinfnav.core.exceptions import InputError
from hinfnav.core.tomlfile import check_schema
from hinfnav.systems import read_system_file
from hinfnav.systems.files import SYSTEM_SCHEMA

NOMINAL = "dt = 0.1\n[nominal]\nA = [[0.5]]\nB = [[1.0]]\nC = [[1.0]]\nD = [[1.0]]\nL = [[1.0]]\n"
NORM = NOMINAL + '[uncertainty]\nkind = "norm-bounded"\nH = [[0.1]]\nE = [[1.0]]\n'


@pytest.mark.parametrize("text, words", [
    (NOMINAL.replace("A = [[0.5]]", "A = [[true]]"), r"A\[0\]\[0\] is the boolean true"),
    (NORM + "dt = 0.2\n", r"uncertainty: unknown key 'dt'"),                            # dt inside [uncertainty]
    (NORM + 'lyapunov = "common"\n', r"uncertainty: unknown key 'lyapunov'"),
    (NOMINAL + "[nominal]\nA = [[0.4]]\n", "not valid TOML.*twice"),                   # a table given twice
    (NOMINAL.replace("dt = 0.1", "dt = 0.1\ndt = 0.2"), "not valid TOML"),              # a key given twice
    (NOMINAL.replace("dt = 0.1", "dt = true"), "dt must be a number"),
    (NOMINAL.replace("A = [[0.5]]", 'A = [[0.5, "x"]]'), r"A\[0\]\[1\] must be a number"),
    (NOMINAL.replace("A = [[0.5]]", "A = [[0.5], [0.1, 0.2]]"), "rectangular"),
    (NOMINAL + '[uncertainty]\nkind = "polytope"\nH = [[0.1]]\n[[uncertainty.vertices]]\nA = [[0.4]]\n',
     r"\['H'\] do not apply to kind = 'polytope'"),
    (NOMINAL + "unit = 1\n", "unknown key 'unit'"),
])
def test_system_file_mistakes_are_named(tmp_path, text, words):
    f = tmp_path / "sys.toml"
    f.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=words) as info:
        read_system_file(f)
    assert "sys.toml" in str(info.value)


@pytest.mark.parametrize("prefix, enc, words", [
    (b"\xef\xbb\xbf", "utf-8", "UTF-8 byte-order mark"),
    (b"", "utf-16", "UTF-16"),
    (b"", "latin-1", r"byte 0xe9 at offset \d+ \(line 2\)"),
])
def test_encodings_are_named(tmp_path, prefix, enc, words):
    f = tmp_path / "sys.toml"
    f.write_bytes(prefix + (NOMINAL.replace("[nominal]", "# décalage\n[nominal]", 1)
                            .replace("dt = 0.1\n", "dt = 0.1\n# é\n")).encode(enc))
    with pytest.raises(InputError, match=words):
        read_system_file(f)
    spec = tmp_path / "spec.toml"
    spec.write_bytes(f.read_bytes())
    with pytest.raises(InputError, match=words):
        load_campaign(spec)


def test_schema_takes_a_new_key_in_one_line():
    schema = {**SYSTEM_SCHEMA, "continuous": "bool"}  # what another issue adds
    check_schema({"dt": 0.0, "continuous": True}, schema)
    with pytest.raises(InputError, match="continuous must be true or false"):
        check_schema({"continuous": 1}, schema)
