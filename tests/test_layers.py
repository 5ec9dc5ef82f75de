"""The package's shape: one-way layers, no import cycle, no module over 600 lines.

Sources: the layer order of issue 7 (core → systems → noise → analysis → lmi →
io → design → estimators → control → sim → metrics → plotting → campaign →
papers → cli; io added by issue 23), written as import-linter contracts in
``pyproject.toml``, which also holds the papers' independence contract (with its
declared crossings) and the no-cycle contract (import-linter's ``acyclic_siblings``,
issue 23); :func:`test_lint_imports_contracts_kept` runs them all. That the layers
also hold at import time is ``tests/test_import_time.py``.
"""

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "hinfnav"

#: Function-local imports allowed, and why: the command line's deferred imports that keep
#: ``python -m hinfnav --help`` fast, and heavy optional libraries loaded only where used
#: (notebook execution, figure objects). A function-local import of the package itself
#: anywhere else would dodge an import cycle: refused.
LOCAL_IMPORT_ALLOWED = {"hinfnav/cli.py": "deferred imports: each command loads only the layers it needs"}
HEAVY_OPTIONAL = ("nbformat", "nbclient", "matplotlib", "papermill", "distributed", "dask",
                  "numba")  # the compiled backend, imported only when backend="numba"/"auto" asks for a kernel


def _modules():
    return sorted(PACKAGE.rglob("*.py"))


def test_lint_imports_contracts_kept():
    exe = shutil.which("lint-imports") or str(Path(sys.executable).with_name("lint-imports"))
    proc = subprocess.run([exe], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert "broken" not in proc.stdout.split("Contracts:")[-1].replace("0 broken", "")


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_module_at_most_600_lines(path):
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= 600, f"{path.relative_to(ROOT)} has {n} lines (limit 600): split it by concept"


def test_no_function_local_import_of_the_package_outside_the_allowed_places():
    offenders = []
    for path in _modules():
        rel = str(path.relative_to(ROOT))
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for sub in ast.walk(node):
                if isinstance(sub, (ast.Import, ast.ImportFrom)) and rel not in LOCAL_IMPORT_ALLOWED:
                    mod = sub.module if isinstance(sub, ast.ImportFrom) else sub.names[0].name
                    external = isinstance(sub, ast.Import) or sub.level == 0
                    if not (external and (mod or "").split(".")[0] in HEAVY_OPTIONAL):
                        offenders.append(f"{rel}:{sub.lineno}")
    assert not offenders, "function-local imports (move them to the top of the module): " + ", ".join(offenders)


def test_generic_layers_never_default_to_the_paper_scenario():
    # Generic code reads dimensions from system objects: no module outside papers/ and cli.py
    # may construct Sun et al. (2011)'s Scenario or import its constants.
    offenders = []
    for path in _modules():
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("hinfnav/papers/") or rel in ("hinfnav/cli.py", "hinfnav/__init__.py"):
            continue
        text = path.read_text(encoding="utf-8")
        if "Scenario()" in text or "sun2011" in text:
            offenders.append(rel)
    assert not offenders, f"generic modules that refer to the Sun 2011 scenario: {offenders}"
