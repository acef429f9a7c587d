"""The runs of ``pushrecovery humanoid campaign``: the spec, the confusion matrix, its lines.

``humanoid campaign --model biped3d|g1 --azimuths 0:360:30 --fraction 0.5 2 0.5 --strategy
step``: the grid of azimuths × pushes under the whole-body controller
(:mod:`pushrecovery.campaign.spec.humanoid`, :mod:`pushrecovery.campaign.pushes.humanoid`);
the command is in :mod:`pushrecovery.cli.humanoid`. :func:`write_confusion` is also the
confusion campaign's of ``humanoid validate``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

__all__ = ["echo_causes", "spec_3d", "write_confusion"]


def spec_3d(model: str, params: Any, strategy: str | None, **options: Any) -> Any:
    """Return the CampaignSpec of a 3-D campaign: the standing body, the whole-body controller.

    Parameters
    ----------
    model : str
        ``biped3d``, ``g1`` or ``mjcf`` (with ``mjcf=`` the file's MjcfSource in ``options``).
    params : BodyParams
        The body (:func:`pushrecovery.cli.humanoid.bodies.body_3d`).
    strategy : str or None
        ``--strategy``: the controller ``wbc-STRATEGY`` (None: ``wbc-step``).
    **options
        The rest of the spec: ``impulse``, ``fraction``, ``azimuths``, ``sweeps``,
        ``samples``, ``seed``, ``duration``, ``batch_size``, ``push_timeout``, ``mjcf``.

    Returns
    -------
    CampaignSpec
        On the MuJoCo backend, from the standing posture (``x0`` 0).

    Raises
    ------
    InvalidParameterError
        If the spec is not one (``CampaignSpec``'s checks).
    """
    from pushrecovery.campaign import CampaignSpec

    return CampaignSpec(
        backend="mujoco",
        model=model,
        controller=f"wbc-{strategy or 'step'}",
        params=params,
        x0=(0.0, 0.0, 1.0),
        xdot=None,
        **options,
    )


def write_confusion(
    table: Any, model: str, directory: Path, plot: bool = True
) -> tuple[Any, dict[str, str]]:
    """Write a 3-D campaign's confusion matrix (Parquet, CSV, figure); return it and the paths.

    Parameters
    ----------
    table : pyarrow.Table
        The campaign's pushes.
    model : str
        The model's name in the figure (``CampaignSpec.model_name``).
    directory : Path
        Where ``confusion3d.*`` go.
    plot : bool
        Also write ``confusion3d.png``.

    Returns
    -------
    tuple
        The ``Confusion3D`` and {name: path} of the files written.
    """
    from pushrecovery.experiments.confusion3d import confusion_from_rows

    result = confusion_from_rows(table.to_pylist(), model)
    parquet, csv = result.write(directory / "confusion3d")
    files = {"confusion3d": str(parquet), "confusion3d_csv": str(csv)}
    if plot:
        from pushrecovery.plots.common import save_figure
        from pushrecovery.plots.confusion3d import confusion3d_figure

        (figure,) = save_figure(confusion3d_figure(result), directory / "confusion3d", ["png"])
        files["confusion3d_png"] = str(figure)
    return result, files


def echo_causes(result: Any) -> None:
    """Print the agreement of a confusion matrix and its pushes per cause.

    Parameters
    ----------
    result : Confusion3D
        :func:`write_confusion`'s.
    """
    from pushrecovery.cli.options import echo_confusion
    from pushrecovery.experiments.confusion3d import LABELS

    echo_confusion(
        f"corrected for the push's height (rows), agreement {result.accuracy_corrected:.3f}:",
        LABELS,
        result.counts_corrected.tolist(),
        result.apart(corrected=True),
    )
    causes = {k: v for k, v in result.causes().items() if v and k != "agree"}
    click.echo(
        "where they differ: " + (", ".join(f"{k} {v}" for k, v in causes.items()) or "nowhere")
    )
