"""The public API's docstrings: every function and class has one, every physical parameter a unit.

The public API is what the API reference documents (``docs/_ext/pushrecovery_api.py``): the names
in the ``__all__`` of every module of ``pushrecovery`` except the CLI (documented from click), the
compiled kernels and ``__main__``. Each object is checked once, where it is defined, together
with the public methods and properties of a public class (autodoc leaves an undocumented member
out of the reference silently). Each docstring is parsed with ``numpydoc.docscrape``, as the
reference renders it.

A check fails when

(a) a public function, class, method or property has no docstring or an empty summary,
(b) a *physical* parameter (``Parameters``, ``Other Parameters``, and a class's ``Attributes``)
    has a description without a unit, or
(c) a docstring of the reference (a module's, an object's or a member's, or the ``#:`` comment of
    public module data), rendered by numpydoc as Sphinx gets it, is not valid reStructuredText
    for docutils: what the docs build reports (``|θ|`` read as a substitution, a malformed table,
    ``t_`` read as a link target), in seconds where the build takes minutes.

A parameter is physical when its name is in :data:`PHYSICAL_NAMES` or one of its ``_``-separated
words is in :data:`PHYSICAL_WORDS` (``push_time``, ``com_height``, ``min_mos_ap``), its name does
not end in one of :data:`NOT_PHYSICAL_ENDINGS` (the QP's task weights), and its declared type is
numeric (:data:`NUMERIC_TYPE`: a float, an array, or no type given; a flag, a name, a count or an
object carries no unit). A description has a unit when :func:`has_unit` finds one: a unit in
brackets (``[m]``, ``[m/s]``, ``[N s]``, ``[N·m]``, ``[kg m²]``, ``[rad/s]``, ``[Hz]``, ``[-]``
for dimensionless), a compound SI unit in prose (``m/s``, ``N m``, ``N·s``, ``rad/s``, ``kg``,
``Hz``, ``deg``), a unit after a range or after "in" (``in (0, 60] s``, ``in mm``), or the words
dimensionless, fraction or ratio (or a file's own length unit, which the C3D and CSV readers
take as the file gives it).
"""

from __future__ import annotations

import contextlib
import copy
import functools
import importlib
import inspect
import io
import pkgutil
import re
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import docutils.core
import pytest
from docutils import nodes
from docutils.frontend import get_default_settings
from docutils.parsers.rst import Directive, Parser, directives, roles
from numpydoc.docscrape import ClassDoc, FunctionDoc, NumpyDocString
from numpydoc.docscrape_sphinx import SphinxDocString
from sphinx.pycode import ModuleAnalyzer

import pushrecovery

#: Modules left out of the API reference, and so of this test.
EXCLUDED = ("pushrecovery.cli", "pushrecovery.kernels", "pushrecovery.__main__")

#: Words that make a parameter name physical wherever they appear in it (split at ``_``):
#: coordinates and their rates, time, mass, lengths, forces and moments, angles, gains, rates.
PHYSICAL_WORDS = frozenset(
    {
        # positions and their rates (x forward, y left, z up; ``dot`` a time derivative)
        "x", "y", "z", "x0", "y0", "z0", "xdot", "ydot", "zdot", "xdot0", "ydot0", "v0",
        "ap", "ml", "position", "positions", "origin", "origins", "corners", "vertices",
        "points", "com", "cop", "cops", "cmp", "dcm", "xcom", "capture", "foothold",
        "footholds", "ankle", "heel", "toe", "margin", "margins", "mos", "xi",
        # time
        "t", "dt", "time", "times", "duration", "period", "latency", "onset", "touchdown",
        "touchdowns", "clock",
        # mass, lengths, areas
        "mass", "height", "length", "width", "radius", "offset", "offsets", "distance",
        "clearance", "spacing", "lever", "reach", "area", "range", "sink",
        # velocity, acceleration, gravity
        "velocity", "speed", "speeds", "acceleration", "gravity", "g", "omega",
        # forces, moments, impulses, inertia
        "force", "forces", "torque", "torques", "tau", "impulse", "moment", "inertia",
        "wrench", "wrenches",
        # angles
        "angle", "theta", "azimuth", "azimuths", "elevation", "yaw", "tilt", "heading",
        "headings",
        # gains and frequencies
        "stiffness", "damping", "kp", "kd", "frequency", "rate", "hz", "cutoff", "fps", "band",
        "f50", "f95",
        # the named points, spans and times of a run, a plan or a trial
        "anchor", "eye", "lookat", "pelvis", "knee", "drop", "gap", "noise", "push", "quiet",
        "segment", "series", "tail", "taken", "window", "windows", "start", "end", "baseline",
        "longest", "shortest", "predicted", "measured", "corrected", "refit", "contact", "spans",
        "sole", "poses", "support",
    }
)  # fmt: skip

#: Whole names that are physical although none of their words is.
PHYSICAL_NAMES = frozenset(
    {
        "m", "floor", "lift", "sole_lift", "tolerance", "rel_tolerance", "threshold", "bracket",
        "step_tolerance", "critical_tolerance", "tolerance3d", "guess", "hip", "step",
        # a model's states and inputs (positions, angles and their rates; CoPs and torques)
        "state", "states", "initial_state", "inputs", "first_input", "applied",
        # MuJoCo's state and commands: mixed units, which the description must give
        "qpos", "qvel", "qacc", "ctrl",
    }
)  # fmt: skip

#: Name endings that are not physical quantities although a word before them is: the weights
#: of the whole-body QP's tasks (``com_weight``, ``height_weight``: relative, no unit).
NOT_PHYSICAL_ENDINGS = ("_weight", "_weights")

#: A declared type (one of its ``or`` alternatives) that can carry a unit: a float, an array.
NUMERIC_TYPE = re.compile(r"float|array|ndarray|number|^\(float")
#: ... unless it holds flags, names, counts or indices (``ndarray of bool``, ``int arrays``).
NON_NUMERIC_TYPE = re.compile(r"\b(bool|str|int\d*|callable|path|Path)\b|^\{")

#: Unit symbols accepted in brackets, joined by spaces, ``·``, ``/``, powers and digits.
UNIT_SYMBOLS = frozenset(
    {"m", "mm", "cm", "s", "ms", "kg", "N", "rad", "deg", "Hz", "J", "W", "px", "units", "per"}
)
BRACKETS = re.compile(r"\[([^\[\]]*)\]")
BRACKET_CONTENT = re.compile(r"[A-Za-z0-9·/^²³⁻¹\s\-−*,.()+]+")
PROSE_UNIT = re.compile(
    r"(?i:\b(?:dimensionless|fraction|ratio|(?:length|point) units?)\b)"
    r"|(?<![\w/])(?:N[ ·]m|N[ ·]s|N/m|kg[ ·]m²|m/s|rad/s|kg|Hz|deg|rad|1/s)(?!\w)"
    r"|(?:[\])]\s*|\bin )(?:m|s|ms|mm|kg|N|rad|deg|Hz)\b"
)


def _bracket_is_unit(content: str) -> bool:
    text = content.strip()
    if text in {"-", "–", "%"}:
        return True
    if not BRACKET_CONTENT.fullmatch(text):
        return False
    symbols = re.findall(r"[A-Za-z]+", text)
    return bool(symbols) and all(symbol in UNIT_SYMBOLS for symbol in symbols)


def has_unit(description: str) -> bool:
    """Whether a parameter's description states its unit (see the module docstring)."""
    if any(_bracket_is_unit(content) for content in BRACKETS.findall(description)):
        return True
    return PROSE_UNIT.search(description) is not None


def is_physical(name: str, type_: str) -> bool:
    """Whether a parameter (its name and declared type) is a physical quantity."""
    if name.endswith(NOT_PHYSICAL_ENDINGS):
        return False
    alternatives = [each.strip() for each in re.split(r"\bor\b", type_)]
    numeric = not type_.strip() or any(
        NUMERIC_TYPE.search(each) and not NON_NUMERIC_TYPE.search(each) for each in alternatives
    )
    return numeric and (
        name in PHYSICAL_NAMES or any(word in PHYSICAL_WORDS for word in name.split("_"))
    )


def _own_doc(obj: Any) -> str | None:
    """The object's own docstring (not a base class's, nor a dataclass's generated one)."""
    if isinstance(obj, property):
        obj = obj.fget
    if inspect.isclass(obj):
        doc = obj.__dict__.get("__doc__")
        if doc and doc.startswith(obj.__name__ + "("):  # dataclass or NamedTuple signature
            return None
        return doc
    return getattr(getattr(obj, "py_func", obj), "__doc__", None)


def _parsed(obj: Any) -> NumpyDocString:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpydoc's "Unknown section" notes
        if inspect.isclass(obj):
            return ClassDoc(obj, config={"show_class_members": False})
        if isinstance(obj, property):
            return NumpyDocString(inspect.cleandoc(_own_doc(obj) or ""))
        return FunctionDoc(getattr(obj, "py_func", obj))


def problems(obj: Any, name: str) -> list[str]:
    """What is wrong with the docstring of ``obj`` (called ``name`` in the messages)."""
    if not (_own_doc(obj) or "").strip():
        return [f"{name}: no docstring"]
    doc = _parsed(obj)
    found = []
    if not " ".join(doc["Summary"]).strip():
        found.append(f"{name}: empty summary")
    for section in ("Parameters", "Other Parameters", "Attributes"):
        for parameter in doc[section]:
            description = " ".join(parameter.desc)
            for each in (part.strip() for part in parameter.name.split(",")):
                if is_physical(each, parameter.type) and not has_unit(description):
                    found.append(f"{name}: {section} {each!r} ({parameter.type}) has no unit")
    return found


def public_modules() -> list[Any]:
    """The modules of the reference: ``pushrecovery`` and its public submodules."""
    names = ["pushrecovery"] + [
        info.name
        for info in pkgutil.walk_packages(pushrecovery.__path__, "pushrecovery.")
        if not info.name.startswith(EXCLUDED)
    ]
    return [
        importlib.import_module(name)
        for name in sorted(names)
        if not any(part.startswith("_") for part in name.split(".")[1:])
    ]


def public_objects() -> dict[str, Any]:
    """Every public function and class, by the dotted name of where it is defined.

    Public methods and properties of a public class follow it (``module.Class.method``).
    """
    found: dict[str, Any] = {}
    seen: set[int] = set()
    for module in public_modules():
        module_name = module.__name__
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            is_routine = inspect.isroutine(obj) or hasattr(obj, "py_func")
            if not (inspect.isclass(obj) or is_routine) or id(obj) in seen:
                continue
            home = getattr(obj, "__module__", None) or module_name
            if not home.startswith("pushrecovery"):
                continue  # an alias of a builtin or third-party class (``Direction = str``)
            seen.add(id(obj))
            qualified = f"{home}.{getattr(obj, '__qualname__', name)}"
            found[qualified] = obj
            if inspect.isclass(obj):
                found.update(_public_members(obj, qualified))
    return found


def _public_members(cls: type, qualified: str) -> Iterator[tuple[str, Any]]:
    for name, member in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(member, (staticmethod, classmethod)):
            member = member.__func__
        if inspect.isfunction(member) or isinstance(member, property):
            yield f"{qualified}.{name}", member


def _literal_role(
    name: str,
    rawtext: str,
    text: str,
    lineno: int,
    inliner: Any,
    options: Any = None,
    content: Any = None,
) -> tuple[list[nodes.Node], list[Any]]:
    return [nodes.literal(rawtext, text)], []


class _SphinxOnlyDirective(Directive):
    has_content = True
    optional_arguments = 10
    final_argument_whitespace = True
    option_spec = None

    def run(self) -> list[nodes.Node]:
        return []


#: Roles and directives Sphinx adds to reStructuredText (docutils alone does not know them).
SPHINX_ROLES = [
    f"{prefix}{role}"
    for prefix in ("", "py:")
    for role in ("func", "class", "meth", "attr", "obj", "mod", "data", "exc", "const")
] + ["ref", "doc", "term", "eq", "numref", "any"]
SPHINX_DIRECTIVES = ["only", "seealso", "versionadded", "versionchanged", "deprecated", "plot"]


@contextlib.contextmanager
def sphinx_markup() -> Iterator[None]:
    """Docutils with Sphinx's roles and directives registered (and unregistered after).

    Docutils has no API to unregister, so its registries are restored from a copy.
    """
    saved_roles, saved_directives = dict(roles._roles), dict(directives._directives)
    for role in SPHINX_ROLES:
        roles.register_local_role(role, _literal_role)
    for directive in SPHINX_DIRECTIVES:
        directives.register_directive(directive, _SphinxOnlyDirective)
    try:
        yield
    finally:
        roles._roles.clear()
        roles._roles.update(saved_roles)
        directives._directives.clear()
        directives._directives.update(saved_directives)


@functools.cache
def _numpydoc_template() -> Any:
    """numpydoc's docstring template, compiled once (numpydoc compiles it per docstring)."""
    return SphinxDocString("").template


@functools.cache
def _docutils_settings() -> Any:
    """Docutils' settings, built once (building them is most of a small docstring's parse)."""
    settings = get_default_settings(Parser)
    settings.report_level = 2  # warnings and errors
    settings.halt_level = 5  # never stop: report them all
    return settings


def rst_problems(text: str, *, numpydoc: bool = True) -> list[str]:
    """What docutils reports on a docstring, rendered by numpydoc first (not for a module)."""
    text = inspect.cleandoc(text)
    if numpydoc:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            text = str(SphinxDocString(text, config={"template": _numpydoc_template()}))
    stream = io.StringIO()
    settings = copy.copy(_docutils_settings())
    settings.warning_stream = stream
    docutils.core.publish_doctree(text, settings=settings)
    return [
        line
        for line in stream.getvalue().splitlines()
        if re.search(r"\((WARNING|ERROR|SEVERE)/", line)
    ]


def reference_docstrings() -> Iterator[tuple[str, str, bool]]:
    """(name, docstring, rendered by numpydoc) of everything the API reference renders."""
    for module in public_modules():
        if not getattr(module, "__all__", None):
            continue
        if module.__doc__:
            yield module.__name__, module.__doc__, False  # numpydoc only strips a module's title
        data = {
            name
            for name in module.__all__
            if not (inspect.isclass(obj := getattr(module, name)) or inspect.isroutine(obj))
        }
        if data:  # the ``#:`` comments (or docstrings) of its public data
            attribute_docs = ModuleAnalyzer.for_module(module.__name__).find_attr_docs()
            for (scope, name), lines in attribute_docs.items():
                if not scope and name in data:
                    yield f"{module.__name__}.{name}", "\n".join(lines), True
    for name, obj in public_objects().items():
        doc = _own_doc(obj)
        if doc:
            yield name, doc, True


@pytest.fixture(scope="module")
def objects() -> dict[str, Any]:
    return public_objects()


def test_the_public_api_is_found(objects: dict[str, Any]) -> None:
    # The walk reaches every floor of the package, each object once where it is defined.
    assert len(objects) > 500
    for name in (
        "pushrecovery.surfaces.classify.classify",
        "pushrecovery.surfaces.monitor.BalanceMonitor",
        "pushrecovery.surfaces.capture.region.capture_region",
        "pushrecovery.analysis.trial.pipeline.analyze",
        "pushrecovery.params.BodyParams",
    ):
        assert name in objects, name
    assert not any(name.startswith(EXCLUDED) for name in objects)


def test_every_public_function_and_class_has_a_docstring(objects: dict[str, Any]) -> None:
    missing = [
        problem
        for name, obj in objects.items()
        for problem in problems(obj, name)
        if problem.endswith(("no docstring", "empty summary"))
    ]
    assert not missing, "\n".join(missing)


def test_every_physical_parameter_has_a_unit(objects: dict[str, Any]) -> None:
    unitless = [
        problem
        for name, obj in objects.items()
        for problem in problems(obj, name)
        if problem.endswith("has no unit")
    ]
    assert not unitless, f"{len(unitless)} without a unit:\n" + "\n".join(unitless)


def test_every_docstring_of_the_reference_is_valid_restructuredtext() -> None:
    found = []
    with sphinx_markup():
        for name, doc, numpydoc in reference_docstrings():
            found += [f"{name}: {problem}" for problem in rst_problems(doc, numpydoc=numpydoc)]
    assert not found, "\n".join(found)


# The checkers themselves: they must be able to fail.


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("Margin = w − |ξ − c| [m].", "Undefined substitution"),
        ("Needs abs(x) < L and a = b |c.", "start-string without end-string"),
        ("The interval [t_-, t_+] of the sole.", "Unknown target name"),
        ("=====  =====\nlonger than its column  x\n=====  =====", "Malformed table"),
        ("Where :unknownrole:`x` is.", "Unknown interpreted text role"),
    ],
)
def test_the_restructuredtext_check_fails_on_what_the_build_rejects(
    text: str, expected: str
) -> None:
    with sphinx_markup():
        found = rst_problems(f"Summary.\n\n{text}\n")
        assert (
            rst_problems("Summary with abs(θ), ``|θ|`` and :func:`~pushrecovery.classify`.") == []
        )
    assert any(expected in problem for problem in found), found


def _undocumented(x: float, xdot: float) -> float:
    return x + xdot


def _unitless(x: float, xdot: float, omega: float) -> float:
    """Capture point of a LIPM state.

    Parameters
    ----------
    x : float
        CoM position relative to the ankle [m].
    xdot : float
        CoM velocity.
    omega : float
        Natural frequency sqrt(g / L) [1/s].
    """
    return x + xdot / omega


class _UnitlessAttribute:
    """A dataclass-like record.

    Attributes
    ----------
    duration : float
        How long it lasts.
    name : str
        Its name (not physical: no unit needed).
    """


def _documented(x: float, xdot: float, omega: float, strategy: str, steps: int) -> float:
    """Capture point of a LIPM state.

    Parameters
    ----------
    x, xdot : float
        CoM position [m] and velocity [m/s].
    omega : float
        Natural frequency sqrt(g / L), in 1/s.
    strategy : str
        ``ankle`` or ``hip`` (a name: no unit).
    steps : int
        A count: no unit.
    """
    return x + xdot / omega


@pytest.mark.parametrize(
    ("function", "expected"),
    [
        (_undocumented, ["_undocumented: no docstring"]),
        (_unitless, ["_unitless: Parameters 'xdot' (float) has no unit"]),
        (_UnitlessAttribute, ["_UnitlessAttribute: Attributes 'duration' (float) has no unit"]),
        (_documented, []),
    ],
)
def test_the_checker_fails_on_a_missing_docstring_or_unit(
    function: Callable[..., Any], expected: list[str]
) -> None:
    assert problems(function, function.__name__) == expected


@pytest.mark.parametrize(
    "description",
    [
        "CoM position relative to the ankle [m].",
        "Push impulse [N s], > 0.",
        "Hip torque [N·m].",
        "Flywheel inertia [kg m²].",
        "Lean rate [rad/s].",
        "Sample rate [Hz].",
        "Share of the limit [-].",
        "Simulated time after the push, in (0, 60] s.",
        "Largest speed, in m/s.",
        "Ratio of the two speeds.",
        "The stiffness k_p in N m/rad.",
        "Corners in the file's length unit.",
    ],
)
def test_a_unit_is_recognised(description: str) -> None:
    assert has_unit(description)


@pytest.mark.parametrize(
    "description",
    [
        "CoM position relative to the ankle.",
        "Bounds [0, 1] of the search.",
        "The states [x, xdot] of the model.",
        "Mass of the body, positive.",
        "See ``params``.",
    ],
)
def test_no_unit_is_recognised(description: str) -> None:
    assert not has_unit(description)


@pytest.mark.parametrize(
    ("name", "type_", "physical"),
    [
        ("push_time", "float", True),
        ("com_height", "float or None", True),
        ("min_mos_ap", "float", True),
        ("headings", "int or array_like", True),  # a count, or the headings [rad]
        ("qpos", "float arrays, shapes (n, nq), (n, nv), (n, nu)", True),
        ("speeds", "", True),  # no type given: checked
        ("com_weight", "float", False),  # a QP task's weight
        ("stance", "bool", False),
        ("support", "Support", False),  # an object: its own docstring has the units
        ("steps", "ndarray of int64", False),
        ("strategy", "str", False),
        ("gamma", "float", False),
    ],
)
def test_the_physical_vocabulary(name: str, type_: str, physical: bool) -> None:
    assert is_physical(name, type_) is physical
