"""The critical push of the 3-D biped from every direction against the 2-D prediction.

For the generated biped (``biped3d``, the paper preset) the example predicts each strategy's
critical impulse at each azimuth from the ground plane's regions (the CoP polygon for the
ankle, the CMP region for the hip), measures it under the whole-body controller in MuJoCo
(ankles only; with the hip task), prints the table, and writes it (markdown) and the polar
plot under out/examples/. Without ``--quick`` it runs every 30° (about a minute) and the G1
(ankle) when the robots extra is installed; ``--quick`` runs the biped's ankle at 0° and 90°.
"""

import argparse
from pathlib import Path

from pushrecovery.experiments.validation3d import DEFAULT_AZIMUTHS, run_validation3d
from pushrecovery.plots.common import save_figure
from pushrecovery.plots.validation3d import validation3d_figure

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--quick", action="store_true", help="biped3d, ankle, 0° and 90° only")
args = parser.parse_args()

out = Path("out/examples")
out.mkdir(parents=True, exist_ok=True)
jobs = (
    [("biped3d", (0.0, 90.0), ("ankle",))]
    if args.quick
    else [("biped3d", DEFAULT_AZIMUTHS, ("ankle", "hip")), ("g1", DEFAULT_AZIMUTHS, ("ankle",))]
)
for model, azimuths, strategies in jobs:
    try:
        result = run_validation3d(model, azimuths, strategies, rel_tolerance=0.01)
    except ImportError as missing:  # the G1 without the robots extra
        print(f"{model}: skipped ({missing})")
        continue
    table = result.to_table()
    print(
        f"{model}: ω = {result.omega:.3f} 1/s, r0 = ({result.origin[0]:.4f}, "
        f"{result.origin[1]:.4f}) m, push lever d = {result.lever:.3f} m, "
        f"z0 = {result.standing_height:.3f} m"
    )
    print(table)
    for strategy in strategies:
        print(
            f"  {strategy}: worst error {100 * result.worst_error(strategy):.1f} % "
            f"(corrected {100 * result.worst_error(strategy, corrected=True):.1f} %)"
        )
    (out / f"validation3d_{model}.md").write_text(table + "\n")
    paths = save_figure(validation3d_figure(result), out / f"validation3d_{model}", ["png"])
    print(f"  wrote {out / f'validation3d_{model}.md'} and {paths[0]}")
