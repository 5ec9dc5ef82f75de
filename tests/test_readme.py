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
