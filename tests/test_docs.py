"""The documentation site builds with warnings as errors (issue 24, item 1).

The fast build, without the notebook chapters (``HINFNAV_DOCS_NOTEBOOKS=0``, as
``python docs/build.py --no-notebooks``); CI's docs step (.ci/run) makes the full build with the
executed notebooks and checks their figures. Expected pages: docs/index.md, docs/api.rst and the
autosummary stubs it generates for each module of the generic layers.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_docs_build_without_warnings_and_hold_the_api(tmp_path):
    out = tmp_path / "html"
    env = dict(os.environ, HINFNAV_DOCS_NOTEBOOKS="0", MPLBACKEND="Agg")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(out)],
        capture_output=True, text=True, env=env, cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]  # -W: any warning fails the build
    assert "<h1>hinfnav" in (out / "index.html").read_text(encoding="utf-8")
    # the API reference: a module page of the design layer documents its exported function
    api = (out / "generated" / "hinfnav.design.robust_hinf.html").read_text(encoding="utf-8")
    assert 'id="hinfnav.design.robust_hinf.synthesize"' in api
    for module in ("systems", "analysis", "design", "estimators", "sim", "metrics", "campaign"):
        assert (out / "generated" / f"hinfnav.{module}.html").exists(), module
    # a README section included in its page (not copied): the test command of the quick start
    assert "pytest" in (out / "quickstart.html").read_text(encoding="utf-8")
    # the fast build says that it has no chapters, rather than showing an empty list
    assert "without the notebooks" in (out / "notebooks.html").read_text(encoding="utf-8")
