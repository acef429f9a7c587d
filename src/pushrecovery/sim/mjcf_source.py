"""A humanoid of the user's own MJCF file, named as a campaign stores it and a worker builds it.

:class:`MjcfSource` is what a 3-D campaign on an MJCF model (``model="mjcf"``) keeps in its spec
(``spec.json``): the file and the bodies that make it a humanoid. Every worker builds the plant
from it (:meth:`MjcfSource.plant`, :class:`~pushrecovery.sim.mujoco.humanoid3d.mjcf.MjcfPlant`);
the file must be readable where the workers run. This module imports no MuJoCo.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pushrecovery.errors import InvalidParameterError, ParameterTypeError

if TYPE_CHECKING:
    from pushrecovery.sim.mujoco.humanoid3d.mjcf import MjcfPlant

__all__ = ["MjcfSource", "model_name"]


def model_name(path: str | Path) -> str:
    """Return the name of MJCF file ``path``'s humanoid: its stem, or a scene's folder's name.

    A ``scene.xml`` (robot and floor, as MuJoCo Menagerie's ``unitree_h1/scene.xml``) takes the
    name of its folder.

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a str or a Path.
    """
    if not isinstance(path, str | Path):
        raise ParameterTypeError(f"path must be a str or a Path, got {type(path).__name__}")
    file = Path(path)
    return file.parent.name if file.stem == "scene" and file.parent.name else file.stem


@dataclass(frozen=True, slots=True)
class MjcfSource:
    """An MJCF humanoid: the file, its feet, its torso and its standing keyframe.

    Attributes
    ----------
    path : str
        The MJCF file, absolute.
    feet : (str, str)
        The left and right foot bodies.
    torso : str
        The upper body (held upright; pushed).
    keyframe : str or None
        The standing pose's keyframe (None: ``qpos0``).

    Raises
    ------
    InvalidParameterError
        If a name is not a non-empty string or ``feet`` not two of them.
    """

    path: str
    feet: tuple[str, str]
    torso: str
    keyframe: str | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.path, str) and self.path) or "\x00" in self.path:
            raise InvalidParameterError(f"path must be an MJCF file's path, got {self.path!r}")
        object.__setattr__(self, "path", str(Path(self.path).expanduser().resolve()))
        feet = self.feet
        if not (isinstance(feet, tuple | list) and len(feet) == 2):
            raise InvalidParameterError(f"feet must be two body names (left, right), got {feet!r}")
        object.__setattr__(self, "feet", (feet[0], feet[1]))
        names = [*self.feet, self.torso] + ([] if self.keyframe is None else [self.keyframe])
        if not all(isinstance(name, str) and name for name in names):
            raise InvalidParameterError(
                "feet, torso and keyframe must be non-empty names, got "
                f"{[n if isinstance(n, str) else type(n).__name__ for n in names]!r}"
            )

    @property
    def name(self) -> str:
        """The name of the campaign's tables and figures (:func:`model_name`)."""
        return model_name(self.path)

    def plant(self) -> MjcfPlant:
        """Build the file's 3-D plant (MuJoCo, the ``sim`` extra).

        Raises
        ------
        InvalidParameterError
            If the file, a body, the keyframe or a leg joint is missing
            (:func:`~pushrecovery.sim.mujoco.humanoid3d.mjcf.describe_mjcf`).
        """
        from pushrecovery.sim.mujoco.humanoid3d.mjcf import MjcfPlant

        return MjcfPlant(self.path, self.feet, self.torso, self.keyframe)

    def to_dict(self) -> dict[str, Any]:
        """JSON form (:meth:`from_dict` reads it back)."""
        return {
            "path": self.path,
            "feet": list(self.feet),
            "torso": self.torso,
            "keyframe": self.keyframe,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MjcfSource:
        """Read :meth:`to_dict`'s form.

        Raises
        ------
        InvalidParameterError
            If a key is missing or a value malformed.
        """
        try:
            return cls(
                path=data["path"],
                feet=tuple(data["feet"]),
                torso=data["torso"],
                keyframe=data.get("keyframe"),
            )
        except (KeyError, TypeError) as exc:
            raise InvalidParameterError(f"malformed MJCF source: {exc!r}") from None
