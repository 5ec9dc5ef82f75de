"""One vocabulary for the papers' verdicts, read from ``summary.json``: the single source of every status line.

Each paper states its verdicts in its own words (Shi 2018: ``reproduced``
true/false per case; paper 002: a text starting "reproduced", "partly
reproduced" or "not reproduced"; Yang 2020: "holds", "holds in part",
"holds under some readings", "does not hold"). :func:`level` maps each to one
of :data:`LEVELS`; :func:`paper_status` reads a paper's ``summary.json``
(as a dict) and returns its claims' levels and the one-line status that the
console prints, the README's status table quotes and the notebooks print.
``summary.json`` carries it as ``status``.

``tests/test_verdicts.py`` fails when the README, a notebook's verdict
statements or the stored status of a full run (:data:`STATUS_FILE`, rewritten
by ``benchmarks/status_snapshot.py`` from a ``reproduce`` output) disagree.
"""

import json
from pathlib import Path

from ..core.exceptions import InputError

__all__ = ["LEVELS", "STATUS_FILE", "format_status", "level", "paper_status", "stored_status"]

#: The three levels, best first.
LEVELS = ("reproduced", "partly", "not reproduced")

#: The status of the full ``python -m hinfnav reproduce`` run (seed 0, default runs) per paper.
STATUS_FILE = Path(__file__).with_name("status_seed0.json")

#: Labels of the claims, per paper, in the order of the paper.
_SHI_LABELS = {"gaussian": "Gaussian gap (§3.1)", "mixture": "mixture (§3.2)", "maneuver": "maneuver (§3.3)"}
_YANG_IDS = ("fig5_l3_vs_l1", "fig5_l1_vs_l2", "fig6", "fig7", "fig8", "fig9", "fig11", "fig12", "asd_vs_pid")
_YANG_LABELS = {"fig5_l3_vs_l1": "Fig 5 L3 more biased than L1", "fig5_l1_vs_l2": "Fig 5 saturation degrades L1 against L2",
                "fig6": "Fig 6", "fig7": "Fig 7", "fig8": "Fig 8", "fig9": "Fig 9 ADRC < PID", "fig11": "Fig 11 (both edges)",
                "fig12": "Fig 12 3e-14", "asd_vs_pid": "ASD ADRC < PID"}


def level(verdict):
    """The level (:data:`LEVELS`) of a verdict: a bool, or a text in one of the papers' vocabularies."""
    if isinstance(verdict, bool):
        return LEVELS[0] if verdict else LEVELS[2]
    if not isinstance(verdict, str):
        raise InputError(f"verdict must be a bool or a text; got {type(verdict).__name__}")
    v = verdict.strip().lower()
    if v.startswith(("partly", "holds in part", "holds under some readings")):
        return LEVELS[1]
    if v.startswith(("not reproduced", "does not hold")):
        return LEVELS[2]
    if v.startswith(("reproduced", "holds")):
        return LEVELS[0]
    raise InputError(f"verdict {verdict!r} is in none of the papers' vocabularies")


def _shi(summary):
    out = []
    for key, label in _SHI_LABELS.items():
        v = summary["verdicts"][key]
        if "verdict" in v:
            lev = level(v["verdict"])
        elif key == "maneuver":
            parts = [v["ekf_faster"], v["hbf_smoother"], v["hbf_final_more_accurate"]]
            lev = LEVELS[0] if all(parts) else LEVELS[1] if any(parts) else LEVELS[2]
        else:
            lev = level(bool(v["reproduced"]))
        out.append({"id": key, "label": label, "verdict": lev})
    return out


def _attitude(summary):
    return [{"id": k, "label": f"claim {k}", "verdict": level(c["verdict"])} for k, c in summary["claims"].items()]


def _yang(summary):
    out = []
    for i, c in enumerate(summary["claims"]):
        cid = c.get("id", _YANG_IDS[i] if i < len(_YANG_IDS) else str(i + 1))
        out.append({"id": cid, "label": _YANG_LABELS.get(cid, c["figure"]), "verdict": level(c["verdict"])})
    return out


_READERS = {"shi2018": _shi, "attitude2018": _attitude, "yang2020": _yang}


def paper_status(key, summary):
    """The claims' levels and the status line of paper ``key`` from its ``summary.json`` (a dict).

    Returns
    -------
    dict
        ``claims``: ``[{"id", "label", "verdict"}]`` in the paper's order, ``verdict`` in :data:`LEVELS`;
        ``line``: the claims grouped by level, e.g. ``"reproduced: mixture (§3.2); partly: maneuver (§3.3);
        not reproduced: Gaussian gap (§3.1)"`` (empty levels left out).
    """
    if key not in _READERS:
        raise InputError(f"key must be one of {sorted(_READERS)} (papers with claim verdicts); got {key!r}")
    claims = _READERS[key](summary)
    groups = [f"{lev}: " + ", ".join(c["label"] for c in claims if c["verdict"] == lev)
              for lev in LEVELS if any(c["verdict"] == lev for c in claims)]
    return {"claims": claims, "line": "; ".join(groups)}


def format_status(key, status):
    """The status as printed on the console: one line per claim, then the summary line."""
    lines = [f"{key}: {c['label']}: {c['verdict']}" for c in status["claims"]]
    return "\n".join(lines + [f"{key} status: {status['line']}"])


def stored_status():
    """The stored status of the full run (:data:`STATUS_FILE`): ``{key: status}``."""
    return json.loads(STATUS_FILE.read_text(encoding="utf-8"))
