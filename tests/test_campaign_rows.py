"""The rows' columns and schemas (campaign/rows.py): one per family, self-describing, in order."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign import CampaignSpec, run_campaign
from pushrecovery.campaign.execute import finish
from pushrecovery.campaign.rows import COLUMNS, PARAM_UNITS, columns, row_schema
from pushrecovery.params import BodyParams

P = load_params()
CAMPAIGN = Path(__file__).parents[1] / "src" / "pushrecovery" / "campaign"


def _module(path: Path) -> str:
    """The dotted name of a module of pushrecovery.campaign, a package by its own name."""
    parts = path.relative_to(CAMPAIGN).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Modules of pushrecovery.campaign that ``path`` imports, at any depth of its code."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            if node.module == "pushrecovery.campaign":
                found.update(alias.name for alias in node.names)
            elif node.module.startswith("pushrecovery.campaign."):
                found.add(node.module.removeprefix("pushrecovery.campaign."))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("pushrecovery.campaign."):
                    found.add(alias.name.removeprefix("pushrecovery.campaign."))
    return found


def test_no_module_of_the_campaign_imports_itself_back() -> None:
    # pushes <-> its 3-D part used to import each other lazily; rows.py holds what they share.
    modules = [p for p in CAMPAIGN.rglob("*.py") if p != CAMPAIGN / "__init__.py"]
    graph = {_module(p): _imports(p) - {_module(p)} for p in modules}
    graph = {name: {m for m in deps if m in graph} for name, deps in graph.items()}

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        for nxt in graph[start]:
            if nxt == goal or (nxt not in seen and reaches(nxt, goal, seen | {nxt})):
                return True
        return False

    assert "pushes" not in graph["pushes.humanoid"] and "rows" in graph["pushes.humanoid"]
    assert "spec.humanoid" in graph["spec"] and "trials.rows" in graph["trials"]
    assert [name for name in graph if reaches(name, name, {name})] == []


@pytest.mark.parametrize("family", ["planar", "3d"])
def test_each_family_describes_the_same_columns_in_the_same_order(family: str) -> None:
    schema = row_schema(family, ["toe", "mass"])
    expected = ["index", "param_toe", "param_mass", *(name for name, _ in COLUMNS)]
    assert schema.names == expected
    assert [str(f.type) for f in schema][3:] == [
        {"float64": "double", "int64": "int64", "string": "string", "bool": "bool"}[kind]
        for _, kind in COLUMNS
    ]
    for field in schema:
        assert set(field.metadata) == {b"unit", b"description"}, field.name
        assert field.metadata[b"unit"] and field.metadata[b"description"], field.name
    assert schema.field("param_mass").metadata[b"unit"] == b"kg"
    assert schema.field("azimuth").metadata[b"unit"] == b"deg"
    assert [c.name for c in columns(family, ["toe", "mass"])] == expected


def test_the_3d_family_reads_some_columns_in_3d() -> None:
    planar, three_d = row_schema("planar"), row_schema("3d")
    assert planar.equals(three_d)  # the same names and types: one contract
    assert not planar.equals(three_d, check_metadata=True)
    assert b"ankle" in planar.field("x0").metadata[b"description"]
    assert b"ground point" in three_d.field("x0").metadata[b"description"]
    assert b"null on the planar" in planar.field("y0").metadata[b"description"]


def test_every_sweepable_parameter_has_a_unit() -> None:
    sweepable = {f.name for f in dataclasses.fields(BodyParams)} - {"foot_polygon"}
    assert set(PARAM_UNITS) == sweepable


def test_bad_families_and_sweeps_are_refused_by_name() -> None:
    with pytest.raises(InvalidParameterError, match="family must be one of"):
        row_schema("2d")
    with pytest.raises(InvalidParameterError, match="family must be one of"):
        columns("sagittal")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="sweeps must be BodyParams fields"):
        row_schema("planar", ["wingspan"])
    with pytest.raises(InvalidParameterError, match="sweeps must be"):
        columns("3d", ["foot_polygon"])


def test_the_parquet_file_explains_its_columns(tmp_path: Path) -> None:
    spec = CampaignSpec(
        "analytic", "pendulum", "ankle-pd", P, x0=(0.0, 0.05, 0.05), xdot=(0.0, 0.4, 0.2),
        sweeps={"toe": (0.15, 0.16, 0.01)},
    )  # fmt: skip
    result = run_campaign(spec, tmp_path / "c", workers=1, isolated=False)
    assert result is not None
    before = pq.read_table(result.pushes_file)
    read = before.schema
    assert read.field("x0").metadata == {
        b"unit": b"m",
        b"description": b"CoM position before the push, relative to the ankle",
    }
    assert read.field("param_toe").metadata[b"unit"] == b"m"
    # A batch written before the metadata (an old campaign, resumed) joins the same file.
    batch = tmp_path / "c" / "batches" / "batch-000000.parquet"
    table = pq.read_table(batch)
    pq.write_table(table.replace_schema_metadata(None).cast(pa.schema(list(
        pa.field(f.name, f.type) for f in table.schema
    ))), batch)  # fmt: skip
    assert pq.read_schema(batch).field("x0").metadata is None
    again = finish(spec, tmp_path / "c")
    assert pq.read_schema(again.pushes_file).field("x0").metadata[b"unit"] == b"m"
    assert pq.read_table(again.pushes_file).equals(before)


def test_planar_mujoco_rows_carry_the_physical_checks(tmp_path: Path) -> None:
    # The same pushes on the analytic flywheel and the MuJoCo torso (the loop engine audits
    # every physics step): the MuJoCo rows have the checks, the analytic ones nulls; each
    # row's checks are those of the same push simulated alone.
    from pushrecovery.campaign.rows import COLUMNS_PHYSICS
    from pushrecovery.control import make_controller
    from pushrecovery.sim.critical import pushed_state
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate

    tables = {}
    for backend, model in (("analytic", "flywheel"), ("mujoco", "torso")):
        spec = CampaignSpec(
            backend, model, "mpc", P, x0=(0.0, 0.0, 0.1), xdot=(0.2, 0.6, 0.4), duration=4.0
        )
        result = run_campaign(spec, tmp_path / backend, workers=1, isolated=False)
        assert result is not None
        tables[backend] = pq.read_table(result.pushes_file).to_pylist()
    for row in tables["analytic"]:
        assert all(row[name] is None for name in COLUMNS_PHYSICS)
    for row in tables["mujoco"]:
        plant = make_plant("torso", P, "mujoco")
        state = pushed_state(plant, row["x0"], row["xdot"], force=True)
        alone = simulate(plant, make_controller("mpc", P), state, duration=4.0)
        assert row["outcome"] == alone.outcome.value
        assert row["foot_slip"] == alone.physics.foot_slip > 0.0
        assert row["peak_ground_force"] == alone.physics.peak_force_ratio > 0.9
        assert row["joint_limit_steps"] == alone.physics.joint_limit_steps
