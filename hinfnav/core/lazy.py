"""Lazy package exports (PEP 562): a package's public names load on first use.

A layer's ``__init__`` that imported every submodule eagerly made ``import
hinfnav.estimators`` load python-control and matplotlib, and ``import
hinfnav.sim`` load cvxpy, through chains no one asked for. A lazy package writes
its exports once, as the imports of an ``if TYPE_CHECKING:`` block: static type
checkers read them there, and :func:`lazy_exports` reads the same block from the
package's source, imports nothing, and loads a submodule only when one of its
names is first read (the approach of scientific-python's SPEC 1 / ``lazy_loader``,
with the stub inside the ``__init__``).

Example (a package's ``__init__.py``)::

    from typing import TYPE_CHECKING

    from ..core.lazy import lazy_exports

    if TYPE_CHECKING:
        from .montecarlo import simulate
        from .truth import TruthModel

    __all__ = ["simulate", "TruthModel"]

    __getattr__, __dir__ = lazy_exports(__name__)
"""

from __future__ import annotations

import ast
import importlib
import sys
import types
from collections.abc import Callable
from pathlib import Path

from .exceptions import HinfnavError

__all__ = ["exported_from", "lazy_exports", "type_checking_imports"]


def type_checking_imports(path: str | Path) -> dict[str, str]:
    """The names imported in the top-level ``if TYPE_CHECKING:`` block of the module at ``path``.

    Returns
    -------
    dict
        Name -> the module it is imported from, relative as written (``".truth"``, ``"..lmi.solve"``).

    Raises
    ------
    HinfnavError
        The module has no such block, or the block holds anything but ``from … import …``.
    """
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            out = {}
            for stmt in node.body:
                if not isinstance(stmt, ast.ImportFrom):
                    raise HinfnavError(f"{path}: only 'from … import …' may stand in the TYPE_CHECKING block")
                for alias in stmt.names:
                    out[alias.asname or alias.name] = "." * stmt.level + (stmt.module or "")
            return out
    raise HinfnavError(f"{path}: a lazy package lists its exports in an 'if TYPE_CHECKING:' block; none found")


class _LazyPackage(types.ModuleType):
    """A package module whose exported names win over its same-named submodules.

    Importing a submodule sets it as an attribute of its package (``hinfnav.analysis.error_system``
    the module), which would hide the exported function of the same name from the package's
    ``__getattr__``; an eager ``from .error_system import error_system`` overwrote it. Here the
    exported object replaces the submodule as it is set, as the eager import did.
    """

    def __setattr__(self, name: str, value: object) -> None:
        exports = self.__dict__.get("_EXPORTS", {})
        if (isinstance(value, types.ModuleType) and name in exports
                and value.__name__ == f"{self.__name__}.{name}" and hasattr(value, name)):
            value = getattr(value, name)
        super().__setattr__(name, value)


def lazy_exports(package: str) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module-level ``__getattr__`` and ``__dir__`` of a lazy package.

    Parameters
    ----------
    package : str
        The package's ``__name__`` (it must be in ``sys.modules``: call this from its ``__init__``,
        after its ``if TYPE_CHECKING:`` block of exports).

    Returns
    -------
    (__getattr__, __dir__)
        To be bound at the package's top level. A name is imported once, then cached in the
        package's namespace; an unknown name raises AttributeError naming the package. The export
        table (name -> relative module) is kept as the package's ``_EXPORTS``.
    """
    module = sys.modules[package]
    exports = type_checking_imports(module.__file__)
    module._EXPORTS = exports
    module.__class__ = _LazyPackage

    def __getattr__(name: str) -> object:
        source = exports.get(name)
        if source is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(source, package), name)
        setattr(module, name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(module)) | set(exports))

    return __getattr__, __dir__


def exported_from(package: str, source: str) -> list[str]:
    """The names a lazy package exports from ``source``, in the order its ``if TYPE_CHECKING:`` block lists them.

    Lets a package's ``__all__`` take a group of names from its export table instead of typing them a
    second time: ``__all__ = [..., *exported_from(__name__, ".protocols")]``.

    Parameters
    ----------
    package : str
        The package's ``__name__``; :func:`lazy_exports` must have run for it.
    source : str
        The module the names are imported from, relative as written in the block (``".protocols"``).

    Raises
    ------
    HinfnavError
        The package has no export table, or imports nothing from ``source``.
    """
    exports = getattr(sys.modules[package], "_EXPORTS", None)
    if exports is None:
        raise HinfnavError(f"{package}: call lazy_exports(__name__) before exported_from")
    names = [name for name, module in exports.items() if module == source]
    if not names:
        raise HinfnavError(f"{package}: its TYPE_CHECKING block imports nothing from {source!r}")
    return names
