"""Lazy package exports (PEP 562): a package's public names load on first use.

A layer's ``__init__`` that imported every submodule eagerly made ``import
hinfnav.estimators`` load python-control and matplotlib, and ``import
hinfnav.sim`` load cvxpy, through chains no one asked for. A lazy package
lists its exports as ``name -> relative module`` and imports a submodule only
when one of its names is first read; the same names are imported under
``typing.TYPE_CHECKING`` for static type checkers (``tests/test_import_time.py``
keeps the two lists equal).

Example (in a package's ``__init__.py``)::

    _EXPORTS = {"simulate": ".montecarlo", "TruthModel": ".truth"}
    __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
"""

from __future__ import annotations

import importlib
import sys
import types
from collections.abc import Callable, Mapping

__all__ = ["lazy_exports"]


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


def lazy_exports(package: str, exports: Mapping[str, str]) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module-level ``__getattr__`` and ``__dir__`` of a lazy package.

    Parameters
    ----------
    package : str
        The package's ``__name__`` (it must be in ``sys.modules``: call this from its ``__init__``).
    exports : mapping of str to str
        Public name -> the module it comes from, relative to ``package`` (``".truth"``,
        ``"..lmi.solve"``). Keep it as the package's global ``_EXPORTS``.

    Returns
    -------
    (__getattr__, __dir__)
        To be bound at the package's top level. A name is imported once, then cached in the
        package's namespace; an unknown name raises AttributeError naming the package.
    """
    module = sys.modules[package]
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
