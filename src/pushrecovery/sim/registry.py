"""Which plants exist, by backend and name: import strings, loaded on demand.

As Gymnasium's registry: the names cost nothing to list (``pushrecovery --help`` imports no
model), and a plant's module, with MuJoCo for that backend, is imported only when one is
built. The simulation core (:mod:`pushrecovery.sim.plants`, :mod:`pushrecovery.sim.simulate`)
never imports a backend; backends plug in here.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.extras import require
from pushrecovery.sim.mjcf_source import MjcfSource

if TYPE_CHECKING:  # listing the models must not load numpy (pushrecovery --help)
    from pushrecovery.ground.support import Support
    from pushrecovery.params import BodyParams
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant
    from pushrecovery.sim.plants import Plant

__all__ = [
    "MODELS",
    "MUJOCO_3D_MODELS",
    "MUJOCO_MODELS",
    "PLANTS",
    "PLANTS_3D",
    "available_models",
    "make_plant",
    "make_plant3d",
]

#: Backend -> model name -> "module:Class" of its plant.
PLANTS: dict[str, dict[str, str]] = {
    "analytic": {
        "lipm": "pushrecovery.sim.plants:LipmPlant",
        "pendulum": "pushrecovery.sim.plants:PendulumPlant",
        "flywheel": "pushrecovery.sim.plants:FlywheelPlant",
        "stepping": "pushrecovery.sim.stepping_plant:SteppingPlant",
        "stepping-plane": "pushrecovery.sim.plane_stepping:PlaneSteppingPlant",
    },
    "mujoco": {
        "foot": "pushrecovery.sim.mujoco.pendulums:MujocoFootPlant",
        "torso": "pushrecovery.sim.mujoco.pendulums:MujocoTorsoPlant",
        "biped": "pushrecovery.sim.mujoco.biped:MujocoBipedPlant",
    },
}
#: The MuJoCo backend's 3-D humanoids (docs/humanoid3d_pushes.md, "The plants"): their state
#: is the CoM's in 3-D
#: and their controller the whole-body QP, so they are apart from the sagittal models above
#: (``MUJOCO_MODELS``, which the sagittal loop, validation and campaigns iterate).
PLANTS_3D: dict[str, str] = {
    "biped3d": "pushrecovery.sim.mujoco.humanoid3d.plant3d:Biped3DPlant",
    "g1": "pushrecovery.sim.mujoco.humanoid3d.plant3d:G1Plant",
}
#: Models of the analytic backend.
MODELS = tuple(PLANTS["analytic"])
#: Models of the MuJoCo backend (:mod:`pushrecovery.sim.mujoco`).
MUJOCO_MODELS = tuple(PLANTS["mujoco"])
#: The 3-D models of the MuJoCo backend (``make_plant(name, params, "mujoco")`` builds them).
MUJOCO_3D_MODELS = tuple(PLANTS_3D)


def available_models(backend: str) -> tuple[str, ...]:
    """Return the model names of ``backend`` (``analytic`` or ``mujoco``).

    Raises
    ------
    ParameterTypeError
        If ``backend`` is not a str.
    InvalidParameterError
        If it names no backend.
    """
    if not isinstance(
        backend, str
    ):  # checked here: pushrecovery.arguments would load numpy (--help)
        raise ParameterTypeError(f"backend must be a str, got {type(backend).__name__}")
    if backend not in PLANTS:
        raise InvalidParameterError(f"backend must be one of {list(PLANTS)}, got {backend!r}")
    return tuple(PLANTS[backend])


def make_plant(
    name: str, params: BodyParams, backend: str = "analytic", *, support: Support | None = None
) -> Plant:
    """Build the plant ``name`` of ``backend``; unknown names raise, naming the choices.

    The MuJoCo backend also builds the 3-D models of :data:`PLANTS_3D` (the G1's ``params``
    must be ``robot_params("g1")``); it needs the ``sim`` extra (``MissingExtraError``
    otherwise, naming it). ``support`` (the ``stepping-plane`` model only) is the stance and
    foot poses every run starts on
    (:attr:`~pushrecovery.sim.plane_stepping.PlaneSteppingPlant.start_support`).
    """
    from pushrecovery.arguments import require_type
    from pushrecovery.params import BodyParams as Body  # a runtime check, not an annotation

    require_type("name", name, str)
    require_type("params", params, Body)
    models = available_models(backend) + (MUJOCO_3D_MODELS if backend == "mujoco" else ())
    table = PLANTS[backend] | (PLANTS_3D if backend == "mujoco" else {})
    if name not in models:
        every = PLANTS | {"mujoco": PLANTS["mujoco"] | PLANTS_3D}
        other = next((b for b, names in every.items() if b != backend and name in names), None)
        hint = f" ({name!r} is a {other} model: use backend {other!r})" if other else ""
        raise InvalidParameterError(
            f"model must be one of {list(models)} for the {backend} backend, "
            f"got model={name!r}{hint}"
        )
    if support is not None and (backend, name) != ("analytic", "stepping-plane"):
        raise InvalidParameterError(
            f"a support (stance and foot poses) applies to the stepping-plane model only, "
            f"got model={name!r}"
        )
    if backend == "mujoco":
        require("sim", "mujoco")
    module, _, attribute = table[name].partition(":")
    kind = getattr(importlib.import_module(module), attribute)
    plant: Plant = kind(params) if support is None else kind(params, support=support)
    return plant


def make_plant3d(name: str | MjcfSource, params: BodyParams) -> Humanoid3DPlant:
    """Build the 3-D humanoid ``name`` of :data:`PLANTS_3D` (a MuJoCo plant) with its own type.

    :func:`make_plant` with the MuJoCo backend, for callers that use what only the 3-D plants
    have (the whole-body controller, pushes from any azimuth). An
    :class:`~pushrecovery.sim.mjcf_source.MjcfSource` builds its file's plant, with the
    file's own body (``params`` is not used).

    Raises
    ------
    InvalidParameterError
        If ``name`` is not one of :data:`MUJOCO_3D_MODELS`, or the MJCF file's plant does not
        build (:meth:`MjcfSource.plant <pushrecovery.sim.mjcf_source.MjcfSource.plant>`).
    """
    from pushrecovery.arguments import require_type

    if isinstance(name, MjcfSource):
        return name.plant()
    require_type("name", name, str)
    if name not in MUJOCO_3D_MODELS:
        raise InvalidParameterError(
            f"model must be one of {list(MUJOCO_3D_MODELS)} (a 3-D humanoid), got model={name!r}"
        )
    plant: Humanoid3DPlant = make_plant(name, params, "mujoco")  # type: ignore[assignment]
    return plant
