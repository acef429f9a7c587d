"""The push directions of the 3-D humanoids' commands: ``--azimuth DEG`` or ``--azimuths GRID``.

``humanoid campaign`` and ``humanoid validate`` take one direction or a grid of them
(:func:`pushrecovery.campaign.spec.humanoid.azimuth_grid`: ``START:STOP:STEP`` or ``A,B,...``).
"""

from __future__ import annotations

__all__ = ["azimuths_from"]


def azimuths_from(azimuth: float | None, azimuths: str | None) -> tuple[float, ...] | None:
    """Return the directions of ``--azimuth DEG`` or ``--azimuths GRID`` (not both), or None.

    Parameters
    ----------
    azimuth : float or None
        ``--azimuth`` [deg].
    azimuths : str or None
        ``--azimuths``: ``START:STOP:STEP`` (a full turn's STOP, 360, left out) or ``A,B,...``.

    Returns
    -------
    tuple of float or None
        The directions [deg], or None if neither option is given.

    Raises
    ------
    InvalidParameterError
        If both are given, or a direction is out of [-360, 360] or repeats.
    """
    from pushrecovery.campaign.spec.humanoid import azimuth_grid, check_azimuths
    from pushrecovery.errors import InvalidParameterError

    if azimuth is not None and azimuths is not None:
        raise InvalidParameterError("give --azimuth DEG or --azimuths GRID, not both")
    if azimuths is not None:
        return azimuth_grid(azimuths)
    return None if azimuth is None else check_azimuths([azimuth], "--azimuth")
