"""Build the documentation site: ``python docs/build.py`` (issue 24).

1. Executes every notebook of ``notebooks/`` with nbclient into ``build/executed/`` (two at a time),
   except those whose executed copy is newer than both the notebook and every file of the package
   (an up-to-date copy is reused, so a second build executes nothing);
2. copies the executed notebooks into ``docs/chapters/``, where myst-nb renders them with their
   stored outputs and figures (``nb_execution_mode = "off"``: Sphinx executes nothing); the kernels
   draw with matplotlib's inline backend, so every figure is stored as a PNG;
3. runs ``sphinx-build -W --keep-going -b html docs build/html`` (warnings are errors);
4. checks that every chapter whose executed notebook holds a figure shows an ``<img>`` in its page,
   and that no figure was stored as its text ``<Figure size ...>``.

``--no-notebooks`` builds the site without the chapters (seconds, not minutes); ``--jobs N`` sets
the notebooks executed at a time (default 2). The site is then at ``build/html/index.html``.
"""

import argparse
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = ROOT / "notebooks"
EXECUTED = ROOT / "build" / "executed"
CHAPTERS = ROOT / "docs" / "chapters"
HTML = ROOT / "build" / "html"
TIMEOUT_S = 900  # per cell, s (the test suite's notebook items use the same)
INLINE_BACKEND = "module://matplotlib_inline.backend_inline"


def _newest_source_mtime():
    """Newest modification time of the package's files: a change there outdates every executed copy."""
    return max(p.stat().st_mtime for p in (ROOT / "hinfnav").rglob("*") if p.is_file() and "__pycache__" not in p.parts)


def _is_up_to_date(notebook, package_mtime):
    out = EXECUTED / notebook.name
    return out.exists() and out.stat().st_mtime > max(notebook.stat().st_mtime, package_mtime)


def execute_notebook(notebook, executed_dir=EXECUTED):
    """Execute one notebook in its own folder and write the executed copy atomically into ``executed_dir``.

    The test suite's notebook items (``notebooks/conftest.py``) call this too, so a CI run executes each
    notebook once: the docs then reuse the copies the tests wrote. The execution is the package's
    (:func:`hinfnav.papers.notebooks.execute_notebook`: a client that reads each reply when it arrives,
    and fails loudly on a kernel that does not go idle or a run much longer than its cells). Returns
    ``(name, seconds)``; a failing cell raises nbclient's ``CellExecutionError`` and writes no copy.
    """
    from hinfnav.papers.notebooks import execute_notebook as run

    notebook = Path(notebook)
    # --matplotlib=inline and the inline backend in the kernel's environment: a Figure left as a cell's
    # value is drawn as a PNG even where the notebook never imports pyplot (the package builds its figures
    # without pyplot's global state), whatever MPLBACKEND the caller has (CI sets Agg).
    _, seconds = run(notebook, Path(executed_dir) / notebook.name, timeout=TIMEOUT_S, cwd=notebook.parent,
                     extra_arguments=["--matplotlib=inline"], env=dict(os.environ, MPLBACKEND=INLINE_BACKEND))
    return notebook.name, seconds


_execute = execute_notebook


def execute_notebooks(jobs):
    """Execute the notebooks without an up-to-date executed copy; return the names executed."""
    EXECUTED.mkdir(parents=True, exist_ok=True)
    package_mtime = _newest_source_mtime()
    todo = [nb for nb in sorted(NOTEBOOKS.glob("*.ipynb")) if not _is_up_to_date(nb, package_mtime)]
    print(f"docs: {len(todo)} notebook(s) to execute, {jobs} at a time", flush=True)
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for name, seconds in pool.map(_execute, todo):
            print(f"docs: executed {name} in {seconds:.0f} s", flush=True)
    return [nb.name for nb in todo]


def copy_chapters():
    """Mirror build/executed/ into docs/chapters/ (only the notebooks that still exist in notebooks/)."""
    shutil.rmtree(CHAPTERS, ignore_errors=True)
    CHAPTERS.mkdir(parents=True)
    for nb in sorted(NOTEBOOKS.glob("*.ipynb")):
        shutil.copy2(EXECUTED / nb.name, CHAPTERS / nb.name)


def check_figures():
    """Every chapter whose executed notebook has an image output must show an <img> in its HTML page."""
    import nbformat

    missing, with_figures, as_text = [], 0, []
    for nb in sorted(CHAPTERS.glob("*.ipynb")):
        cells = nbformat.read(nb, as_version=4).cells
        if any(str(out.get("data", {}).get("text/plain", "")).startswith("<Figure size")
               and "image/png" not in out.get("data", {})
               for cell in cells if cell.cell_type == "code" for out in cell.get("outputs", [])):
            as_text.append(nb.name)  # a figure stored as its text repr: the kernel did not draw inline
        has_image = any("image/png" in out.get("data", {}) or "image/svg+xml" in out.get("data", {})
                        for cell in cells if cell.cell_type == "code" for out in cell.get("outputs", []))
        if not has_image:
            continue
        with_figures += 1
        page = HTML / "chapters" / f"{nb.stem}.html"
        if "<img" not in page.read_text(encoding="utf-8"):
            missing.append(page.name)
    if missing or as_text or not with_figures:
        sys.exit(f"docs: no <img> in the rendered chapters {missing}, figures stored as text in {as_text} "
                 f"(chapters with figures: {with_figures})")
    print(f"docs: {with_figures} chapters show their figures", flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-notebooks", action="store_true", help="build the site without the notebook chapters")
    parser.add_argument("--jobs", type=int, default=2, help="notebooks executed at a time (default 2)")
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs must be at least 1, got {args.jobs}")
    start = time.perf_counter()
    env = dict(os.environ, MPLBACKEND="Agg")
    if args.no_notebooks:
        env["HINFNAV_DOCS_NOTEBOOKS"] = "0"
    else:
        execute_notebooks(args.jobs)  # the kernels draw inline (execute_notebook), whatever MPLBACKEND is
        copy_chapters()
        env["HINFNAV_DOCS_NOTEBOOKS"] = "1"
    t_sphinx = time.perf_counter()
    subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                    str(ROOT / "docs"), str(HTML)], check=True, env=env)
    print(f"docs: sphinx-build took {time.perf_counter() - t_sphinx:.0f} s", flush=True)
    if not args.no_notebooks:
        check_figures()
    print(f"docs: built {HTML / 'index.html'} in {time.perf_counter() - start:.0f} s", flush=True)


if __name__ == "__main__":
    main()
