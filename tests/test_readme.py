"""The README's library quick start runs as printed (source: README.md itself)."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_library_quick_start_runs_verbatim(tmp_path, monkeypatch, capsys):
    text = README.read_text(encoding="utf-8")
    section = text.split("## Library quick start", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "certified gamma = 0.35" in out  # γ*(0.3) = 0.3589 (notebook 03, Corollary 1)
    assert "RMS position (m):" in out and "6 states, dt = 0.1" in out
    assert (tmp_path / "design.json").is_file()


def test_your_own_system_runs_verbatim(capsys):
    text = README.read_text(encoding="utf-8")
    section = text.split("## Your own system", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert len([line for line in code.splitlines() if line.strip()]) <= 12  # the section's promise: a short example
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    # both filters track the noise-free turn: after 100 s the error is of the order of the sensor's
    # cross-range noise (0.01 rad at ~1 km: 10 m); 30 m fails a diverged or mis-wrapped filter
    for name in ("ExtendedKalmanFilter", "SigmaPointFilter"):
        err = float(re.search(rf"{name} final position error \(m\): ([0-9.]+)", out).group(1))
        assert err < 30.0, out
