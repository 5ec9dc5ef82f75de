"""Saving figures with their provenance in the file's metadata."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["save_figure"]


def save_figure(fig: Figure, out_dir: str | os.PathLike[str], name: str, provenance: Mapping[str, Any] | None = None, *,
                formats: Sequence[str] = ("png", "pdf"), dpi: int = 130) -> list[Path]:
    """Save ``fig`` as ``out_dir/name.<ext>`` for each format; return the paths.

    The provenance dict (see :func:`hinfnav.io.provenance.provenance`) goes into
    the PNG ``Description`` and the PDF ``Subject``, the figure's title into ``Title``.
    """
    prov = provenance or {}
    text = json.dumps(prov)
    sup = getattr(fig, "_suptitle", None)
    title = sup.get_text() if sup is not None else name
    creator = f"hinfnav {prov.get('hinfnav', '')}".strip()
    meta = {"png": {"Title": title, "Description": text, "Software": creator},
            "pdf": {"Title": title, "Subject": text, "Creator": creator}}
    paths = []
    for ext in formats:
        path = Path(out_dir) / f"{name}.{ext}"
        fig.savefig(path, dpi=dpi, metadata=meta.get(ext))
        paths.append(path)
    return paths
