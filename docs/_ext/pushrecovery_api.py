"""The ``pushrecovery-api`` directive: the API reference of one subpackage from its ``__all__``.

Each public object is documented once, in the module that defines it; a package that re-exports
it lists the name with a link. The list is read from the modules themselves at build time, so a
name added to an ``__all__`` appears in the reference without editing a page.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
from types import ModuleType
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.parsing import nested_parse_to_nodes

# Subpackages whose objects are not part of the reference: the CLI is documented from click
# (cli.md) and the compiled kernels are an implementation detail behind the public API.
EXCLUDED = ("pushrecovery.cli", "pushrecovery.kernels", "pushrecovery.__main__")


def public_modules(package: str) -> list[ModuleType]:
    """Modules of ``package`` (itself included) with a non-empty ``__all__``, in name order."""
    root = importlib.import_module(package)
    names = [package]
    if hasattr(root, "__path__"):
        names += [m.name for m in pkgutil.walk_packages(root.__path__, package + ".")]
    modules = []
    for name in sorted(names):
        if name.startswith(EXCLUDED) or any(p.startswith("_") for p in name.split(".")[1:]):
            continue
        module = importlib.import_module(name)
        if getattr(module, "__all__", None):
            modules.append(module)
    return modules


def home(module: ModuleType, name: str) -> str:
    """The module that documents ``module.name``: where it is defined, else ``module``."""
    obj = getattr(module, name)
    defined = getattr(obj, "__module__", None)
    if (
        (inspect.isclass(obj) or inspect.isfunction(obj))
        and defined
        and defined != module.__name__
        and not defined.startswith(EXCLUDED)
    ):
        defining = importlib.import_module(defined)
        if name in getattr(defining, "__all__", ()):
            return defined
    return module.__name__


def entry(module: ModuleType, name: str) -> list[str]:
    """The autodoc directive that documents ``module.name``."""
    obj: Any = getattr(module, name)
    target = f"{module.__name__}.{name}"
    if inspect.isclass(obj):
        return [f".. autoclass:: {target}", "   :members:", "   :show-inheritance:", ""]
    if inspect.isroutine(obj) or hasattr(obj, "py_func"):  # a function or a numba dispatcher
        return [f".. autofunction:: {target}", ""]
    return [f".. autodata:: {target}", "   :no-value:", ""]


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
                if where == module.__name__:
                    lines += entry(module, name)
                else:
                    elsewhere.append(f":py:obj:`{name} <{where}.{name}>`")
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
            obj = getattr(module, name)
            if not (inspect.isclass(obj) or inspect.isroutine(obj) or hasattr(obj, "py_func")):
                continue
            target = f"{home(module, name)}.{name}"
            if target not in documented:
                logger.warning("%s is public but has no entry in the API reference", target)


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the directive and the check that the reference is complete."""
    app.add_directive("pushrecovery-api", PushRecoveryApi)
    app.connect("env-check-consistency", check_every_object_documented)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
