"""Saving figures with their provenance in the file's metadata, and reading it back."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PIL import Image  # matplotlib's own dependency (it writes the PNG files)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

from ..core.exceptions import InputError

__all__ = ["save_figure", "read_provenance"]

#: The PDF Info entry holding the provenance, as matplotlib writes it: a literal string ``(...)``.
_PDF_SUBJECT = re.compile(rb"/Subject \(((?:[^\\)]|\\.)*)\)", re.DOTALL)
_PDF_ESCAPES = {b"n": b"\n", b"r": b"\r", b"t": b"\t", b"b": b"\b", b"f": b"\f", b"(": b"(", b")": b")",
                b"\\": b"\\"}


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


def read_provenance(path: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The provenance dict :func:`save_figure` wrote into a PNG or PDF file, or None when it has none.

    Reads the PNG ``Description`` text chunk (with Pillow, which matplotlib requires) or the PDF
    ``/Subject`` entry of the document information dictionary.

    Raises
    ------
    InputError
        ``path`` is not a ``.png`` or ``.pdf`` file.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".png", ".pdf") or not path.is_file():
        raise InputError(f"path must be a PNG or PDF file written by save_figure; got {path}")
    if suffix == ".png":
        with Image.open(path) as img:
            text = img.text.get("Description")
    else:
        match = _PDF_SUBJECT.search(path.read_bytes())
        text = None if match is None else re.sub(rb"\\(.)", lambda m: _PDF_ESCAPES.get(m.group(1), m.group(1)),
                                                 match.group(1)).decode("latin-1")
    if not text:
        return None
    try:
        prov = json.loads(text)
    except json.JSONDecodeError:
        return None
    return prov if isinstance(prov, dict) and prov else None
