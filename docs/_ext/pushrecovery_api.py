"""The ``pushrecovery-api`` directive: the API reference of one subpackage from its ``__all__``.

Each public object is documented once, in the module that defines it; a package that re-exports
it lists the name with a link. The list is read from the modules themselves at build time, so a
name added to an ``__all__`` appears in the reference without editing a page.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import os
import pkgutil
import re
import typing
from types import ModuleType
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.parsing import nested_parse_to_nodes

# Subpackages whose objects are not part of the reference: the CLI is documented from click
# (cli.md) and the compiled kernels are an implementation detail behind the public API, but for
# the thread cap a balance loop sets (INCLUDED).
EXCLUDED = ("pushrecovery.cli", "pushrecovery.kernels", "pushrecovery.__main__")
INCLUDED = ("pushrecovery.kernels.threads",)


def public_modules(package: str) -> list[ModuleType]:
    """Modules of ``package`` (itself included) with a non-empty ``__all__``, in name order."""
    root = importlib.import_module(package)
    names = [package]
    if hasattr(root, "__path__"):
        names += [m.name for m in pkgutil.walk_packages(root.__path__, package + ".")]
    modules = []
    for name in sorted(names):
        hidden = name.startswith(EXCLUDED) and name not in INCLUDED
        if hidden or any(p.startswith("_") for p in name.split(".")[1:]):
            continue
        module = importlib.import_module(name)
        if getattr(module, "__all__", None):
            modules.append(module)
    return modules


def is_documented_object(obj: Any) -> bool:
    """A class or a function (numba dispatchers included): what gets its own entry."""
    return inspect.isclass(obj) or inspect.isroutine(obj) or hasattr(obj, "py_func")


@functools.cache
def homes() -> dict[int, str]:
    """For each public class and function, the one ``module.name`` that documents it.

    The module that defines it if that module exports it, else the first module (in name
    order) that exports it: a package re-exporting a private module's class documents it.
    """
    found: dict[int, str] = {}
    for module in public_modules("pushrecovery"):
        for name in module.__all__:
            obj = getattr(module, name)
            if not is_documented_object(obj):
                continue
            defined = getattr(obj, "__module__", None) or ""
            if defined != module.__name__ and not defined.startswith(EXCLUDED):
                defining = importlib.import_module(defined)
                own = getattr(obj, "__name__", name)  # an alias (Plant = Backend) is its class
                if own in getattr(defining, "__all__", ()):
                    found[id(obj)] = f"{defined}.{own}"
                    continue
            found.setdefault(id(obj), f"{module.__name__}.{name}")
    return found


def home(module: ModuleType, name: str) -> str:
    """The ``module.name`` that documents ``module.name`` (:func:`homes`; data stays put)."""
    return homes().get(id(getattr(module, name)), f"{module.__name__}.{name}")


def entry(module: ModuleType, name: str) -> list[str]:
    """The autodoc directive that documents ``module.name``."""
    obj: Any = getattr(module, name)
    target = f"{module.__name__}.{name}"
    if inspect.isclass(obj):
        bases = ["   :show-inheritance:"] if obj.__bases__ != (object,) else []
        return [f".. autoclass:: {target}", "   :members:", *bases, ""]
    if is_documented_object(obj):  # a function or a numba dispatcher
        return [f".. autofunction:: {target}", ""]
    if typing.get_origin(obj) is not None:  # a type alias: its value is its documentation
        return [f".. py:data:: {target}", f"   :value: {typing_repr(obj)}", ""]
    return [f".. autodata:: {target}", "   :no-value:", ""]


def typing_repr(alias: Any) -> str:
    """``tuple[float, float]`` rather than the alias's module-qualified repr."""
    return re.sub(r"\b(?:numpy\.typing|numpy|builtins|typing)\.", "", repr(alias))


class PushRecoveryApi(SphinxDirective):
    """``.. pushrecovery-api:: pushrecovery.surfaces``: every public object of a subpackage."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        lines: list[str] = []
        if os.environ.get("PUSHRECOVERY_DOCS_NO_API"):  # a quick build of the prose pages only
            return []
        for module in public_modules(self.arguments[0]):
            title = f"``{module.__name__}``"
            lines += [title, "-" * len(title), ""]
            lines += [f".. automodule:: {module.__name__}", "   :no-members:", ""]
            elsewhere = []
            for name in module.__all__:
                if name.startswith("__"):
                    continue
                where = home(module, name)
                if where == f"{module.__name__}.{name}":
                    lines += entry(module, name)
                else:
                    elsewhere.append(f":py:obj:`{name} <{where}>`")
            if elsewhere:
                lines += ["Also exported here: " + ", ".join(elsewhere) + ".", ""]
            self.env.note_dependency(module.__file__ or "")
        return list(nested_parse_to_nodes(self.state, "\n".join(lines), allow_section_headings=True))


logger = logging.getLogger(__name__)


def check_every_object_documented(app: Sphinx, env: BuildEnvironment) -> None:
    """Warn (an error under ``-W``) for a public function or class the reference lacks."""
    if os.environ.get("PUSHRECOVERY_DOCS_NO_API"):
        return
    documented = set(env.get_domain("py").objects)
    for module in public_modules("pushrecovery"):
        for name in module.__all__:
            if not is_documented_object(getattr(module, name)):
                continue
            target = home(module, name)
            if target not in documented:
                logger.warning("%s is public but has no entry in the API reference", target)


def reread_api_pages(
    app: Sphinx, env: BuildEnvironment, added: set[str], changed: set[str], removed: set[str]
) -> list[str]:
    """Read the API pages again at every build: a new module changes no file they depend on."""
    return sorted(name for name in env.found_docs if name.startswith("api/"))


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the directive and the check that the reference is complete."""
    app.add_directive("pushrecovery-api", PushRecoveryApi)
    app.connect("env-get-outdated", reread_api_pages)
    app.connect("env-check-consistency", check_every_object_documented)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
