"""A paper's claims as a table file (CSV and Markdown), as the papers with a results table write one.

Rows are claim records: ``claim``, ``verdict``, and where the paper's
module gives them ``id``, ``figure``, ``quote`` (the paper's words, original
language), ``quote_en`` (an English rendering), ``statistic``, ``number``
(ours) and ``paper``. Numbers that are dicts or lists are written as compact JSON.
"""

import csv
import io
import json
from pathlib import Path

from ..core.exceptions import InputError
from ..io.outputs import atomic_write_text, to_json

__all__ = ["write_claims_table"]

#: The columns, in order.
CLAIM_COLUMNS = ("id", "figure", "claim", "quote", "quote_en", "statistic", "number", "paper", "verdict")


def _cell(v, limit=None):
    if v is None:
        return ""
    if isinstance(v, (dict, list, tuple)):
        v = json.dumps(to_json(v, strict=True), separators=(",", ":"))
    text = str(v)
    return text if limit is None or len(text) <= limit else text[: limit - 1] + "…"


def claims_rows(claims):
    """One dict per claim with :data:`CLAIM_COLUMNS` from a list of records or a dict id → record."""
    items = claims.items() if isinstance(claims, dict) else enumerate(claims, start=1)
    rows = []
    for key, c in items:
        if not isinstance(c, dict) or "claim" not in c or "verdict" not in c:
            raise InputError(f"claims entry {key!r} must be a dict with 'claim' and 'verdict'")
        rows.append({"id": str(c.get("id", key)), "figure": c.get("figure"), "claim": c["claim"],
                     "quote": c.get("quote"), "quote_en": c.get("quote_en"), "statistic": c.get("statistic"), "number": c.get("number", c.get("ours")),
                     "paper": c.get("paper"), "verdict": c["verdict"]})
    return rows


def format_claims_table(claims, title):
    """The claims as Markdown (numbers shortened to 200 characters; the CSV has them whole; quotes whole)."""
    rows = claims_rows(claims)
    cols = [c for c in CLAIM_COLUMNS if any(r[c] is not None for r in rows)]
    lines = [f"# {title}", "", "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(_cell(r[c], None if c.startswith("quote") else 200).replace("|", "\\|").replace("\n", " ") for c in cols) + " |")
    return "\n".join(lines) + "\n"


def write_claims_table(claims, out_dir, title, name="claims"):
    """Write ``<name>.csv`` and ``<name>.md`` into ``out_dir`` (each atomically); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=CLAIM_COLUMNS)
    writer.writeheader()
    for r in claims_rows(claims):
        writer.writerow({k: _cell(v) for k, v in r.items()})
    csv_path, md_path = out / f"{name}.csv", out / f"{name}.md"
    atomic_write_text(csv_path, buf.getvalue(), newline="")
    atomic_write_text(md_path, format_claims_table(claims, title))
    return csv_path, md_path
