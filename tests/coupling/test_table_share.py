"""The cell table's share of a two-scale run's error (ngcontact.coupling.table_share): on the press fit coupled with
a spectral Westergaard cell (tests/drivers/test_study_kinds.py) ``discretization.tolerance`` refines the table
where the interface's pressures lie, reports its share in ``results.accuracy``, bounds the error against a much
finer table, writes the grown table back to the cache for the next run, and ends with its figures where the
target is out of reach."""
from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from ngcontact.coupling import pressure_table as PT
from ngcontact.coupling import table_share as TS
from ngcontact.drivers import run_macro as D
from ngcontact.drivers import run_two_scale as R
from ngcontact.drivers.macro_geometry import build_geometry
from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import macro_problem as M
from ngcontact.macro.macro_measures import interface_samples
from ngcontact.output.report import Clock, accuracy_line
from ngcontact.scene import loader

from tests.drivers.test_study_kinds import two_scale_scene


def scene_with(tmp_path, monkeypatch, tolerance: float | None = None, table_tol: float = 0.02, gap: float = -1e-3):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    tmp_path.mkdir(exist_ok=True)
    path = two_scale_scene(tmp_path)
    text = path.read_text().replace("table_tol = 0.02", f"table_tol = {table_tol}").replace("gap = -1e-3",
                                                                                           f"gap = {gap!r}")
    if tolerance is not None:
        text = text.replace("maxh = 0.3", f"maxh = 0.3\ntolerance = {tolerance}")
    path.write_text(text)
    return loader.load(path)


def loop(scene, tmp_path):
    """The scene's loop on its own mesh and order (no macro refinement), the cell solves in this process."""
    problem, _ = D.problem_of(scene, build_geometry(scene))
    return R.couple_loop(scene, problem, partial(D.solve_scene, scene), map_tasks=PT.serial_map,
                         cache_dir=str(tmp_path / "cache"))


def reference(sol, table: PT.CellTable, scene, halvings: int):
    """``sol`` solved again with ``table``'s intervals around the interface's pressures halved ``halvings`` times
    (the law there 2^halvings times finer; each halving at least halves its error)."""
    p = interface_samples(sol, scene.output.points_per_element)["pressure"]
    lo, hi = 0.9 * p[p > 0].min(), 1.1 * p.max()
    fine = PT.CellTable(table.response, table.tol, values=dict(table.values))
    for _ in range(halvings):
        P = fine.pressures
        fine._solve([0.5 * (a + b) for a, b in zip(P[:-1], P[1:]) if b >= lo and a <= hi])
    law = il.InterfaceLaw(normal=PT.response_law(fine), friction=sol.problem.law.friction)
    return D.solve_scene(scene, M.replace_law(sol.problem, law), sol.gfu.vec)


def measured(sol, relevel, scene, component: str) -> dict:
    """The quantities of the share on ``sol``: the headline quantities and, where the bodies have singular
    points, the maxima away from them (outside the balls the share took them outside of)."""
    from ngcontact.macro import away_maxima as AM
    out = DE.headlines(sol, scene.output.points_per_element, component)
    if isinstance(relevel.exclusion, AM.Exclusion):
        out.update(AM.away_maxima(sol, relevel.exclusion))
    return out


def test_held_responses_become_nodes_without_a_cell_solve_and_survive_the_cache(tmp_path):
    calls: list[float] = []

    def response(p):
        calls.append(p)
        return {"contact_fraction": min(p, 1.0), "k_n0": 1.0, "g_n0": 0.0, "closure": p + p ** 3}
    table = PT.CellTable(response, tol=1e-2, map_tasks=PT.serial_map)
    table.cover(0.1, 1.0)
    nodes, solved = dict(table.values), len(calls)
    P = table.pressures
    k = int(np.searchsorted(P, 0.5)) - 1                      # the interval holding 0.5 and 0.55
    assert P[k] < 0.5 < 0.55 < P[k + 1]
    mids = table.used_midpoints([0.5, 0.55])                 # it and one neighbour on either side
    assert mids == pytest.approx([0.5 * (P[i] + P[i + 1]) for i in (k - 1, k, k + 1)])
    assert table.used_midpoints([0.5, 0.55], margin=0) == pytest.approx([0.5 * (P[k] + P[k + 1])])
    held = table.hold(mids)
    assert table.values == nodes and set(table.held) == set(mids) and len(calls) == solved + 3
    R.store_table("k" * 64, table, str(tmp_path))
    again, cached = R.cached_table("k" * 64, response, 1e-2, PT.serial_map, str(tmp_path))
    assert cached and again.values == nodes and again.held == held
    again._solve(mids[:1])                                   # a held pressure asked for: a node, not a solve
    assert mids[0] in again.values and set(again.held) == set(mids[1:]) and len(calls) == solved + 3


@pytest.mark.parametrize("gap, least", [(-2e-3, 6), (-1.5e-3, 6), (-1e-3, 1), (-5e-4, 6)])
def test_the_table_share_bounds_its_error_against_a_much_finer_table(tmp_path, monkeypatch, gap, least):
    """Effectivity of the share (the used intervals halved twice) on the scene's mesh: between 1 and 10 on every
    quantity whose error against a much finer table is above round-off (:func:`reference`), at least ``least``
    of them.  At the scene's interference the stresses lie where the cell's law is exact (only the peak
    pressure, at the interface's end, feels the table); at twice it one halving alone underestimates the
    error (the second halving's bound is needed), at 1.5 times it without the neighbouring intervals."""
    scene = scene_with(tmp_path, monkeypatch, gap=gap)
    sol, _, relevel = loop(scene, tmp_path)
    answer = relevel.table_share(sol, 1e-3)
    share = relevel.share
    assert share is not None and share.share <= TS.FRACTION * 1e-3
    ref = reference(answer, relevel.table, scene, 4)
    assert len(ref.problem.law.normal.pressure) > 2 * len(relevel.table.values)
    component = next(k for k in share.values if k.startswith("resultant_")).removeprefix("resultant_")
    ref = measured(ref, relevel, scene, component)
    assert DE.headlines(answer, scene.output.points_per_element, component)["peak_pressure"].value == \
        pytest.approx(share.values["peak_pressure"], rel=1e-12)
    compared = []
    for name, value in share.values.items():
        true = abs(value - ref[name].value)
        if true <= 1e-9 * abs(ref[name].value):             # round-off of the Newton solves
            continue
        compared.append(name)
        assert true <= share.errors[name] <= 10 * true, (name, share.errors[name], true)
    assert "peak_pressure" in compared and len(compared) >= least, compared


def test_a_tolerance_refines_the_table_reports_its_share_and_a_second_run_reuses_it(tmp_path, monkeypatch):
    first = D.run(scene_with(tmp_path, monkeypatch, 1e-3), Clock()).results
    q = {x["name"]: x for x in first["accuracy"]["quantities"]}
    share, own = q["cell_table_share"], q["cell_table_interpolation"]
    assert share["met"] and share["counted"] and share["value"] <= TS.FRACTION * 1e-3 == share["limit"]
    assert "halved" in share["how"] and len(share["rounds"]) >= 2
    assert share["rounds"][0]["share"] > share["limit"]               # the scene's table alone misses it
    assert not own["counted"] and own["value"] > 1e-3                # the table's own error is said, not judged
    assert first["accuracy"]["met"], first["accuracy"]["quantities"]
    assert f"cell_table_interpolation {own['value']:.4g} +/- {own['value']:.2%} not counted" in \
        accuracy_line(first)
    ts = first["two_scale"]
    assert ts["table"]["held"] >= 1 and ts["cell_solves"] > 0
    second = D.run(scene_with(tmp_path, monkeypatch, 1e-3), Clock()).results
    again = {x["name"]: x for x in second["accuracy"]["quantities"]}
    assert second["two_scale"]["cache"]["table_from_cache"] and second["two_scale"]["cell_solves"] == 0
    assert second["two_scale"]["table"]["nodes"] == ts["table"]["nodes"]
    assert again["cell_table_share"]["value"] == pytest.approx(share["value"], rel=1e-6)
    assert again["peak_pressure"]["value"] == pytest.approx(q["peak_pressure"]["value"], rel=1e-9)


def test_a_share_out_of_reach_ends_the_run_with_its_figures(tmp_path, monkeypatch):
    monkeypatch.setattr(TS, "MAX_ROUNDS", 1)
    with pytest.raises(ConvergenceError) as info:
        D.run(scene_with(tmp_path, monkeypatch, 1e-6), Clock())
    said = str(info.value)
    assert "not met by the cell table" in said and "1 halvings are the bound" in said and "nodes" in said
    rounds = info.value.history["table_share"]
    assert len(rounds) == 1 and np.isfinite(rounds[0]["share"]) and rounds[0]["share"] > TS.FRACTION * 1e-6
    # what was solved is cached for the next run
    assert any(p.suffix == ".npz" for p in (tmp_path / "cache").iterdir())


def test_a_table_grown_on_another_macro_level_is_written_back_for_the_next_run(tmp_path, monkeypatch):
    """A mesh level whose pressures the table does not cover grows it (:class:`ngcontact.drivers.run_two_scale.
    Relevel`); the grown table is in the cache at once, so the next run solves none of those cells again."""
    from dataclasses import replace
    scene = scene_with(tmp_path, monkeypatch)
    problem, _ = D.problem_of(scene, build_geometry(scene))
    sol, res, relevel = R.couple_loop(scene, problem, partial(D.solve_scene, scene), map_tasks=PT.serial_map,
                                      cache_dir=str(tmp_path / "cache"))
    nodes = res["table"]["nodes"]
    relevel(replace(problem, gap=2 * problem.gap))           # twice the interference: higher pressures
    assert relevel.loops[-1]["cell_solves"] > 0 and len(relevel.table.values) > nodes
    key = res["cache"]["key"]
    cached, found = R.cached_table(key, relevel.table.response, scene.two_scale.table_tol, PT.serial_map,
                                   str(tmp_path / "cache"))
    assert found and cached.values == relevel.table.values
    again, res2, _ = R.couple_loop(scene, problem, partial(D.solve_scene, scene), map_tasks=PT.serial_map,
                                   cache_dir=str(tmp_path / "cache"))
    assert res2["cache"]["table_from_cache"] and res2["cell_solves"] == 0


# --------------------------------------------------------------------------- the shear table's share
def _friction_block(tmp_path):
    """The sawtooth shear block of ``scripts/sawtooth_shear.py`` (1 x 1 blocks, pressed with 1e-3 and moved by
    0.002 along the interface, part of it sticking) as a two-scale scene under ``friction = "from_cell"``; its
    cell's responses are replaced by the closed forms below (:func:`analytic_tables`)."""
    import importlib.util
    from pathlib import Path
    spec = importlib.util.spec_from_file_location("sawtooth_shear", Path(__file__).parents[2] / "scripts" /
                                                  "sawtooth_shear.py")
    assert spec is not None and spec.loader is not None
    S = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(S)
    tmp_path.mkdir(parents=True, exist_ok=True)
    S.write_cell(str(tmp_path))
    return S.macro_scene(str(tmp_path), *S.VARIANTS["from_cell"], u=0.002)


def normal_response(p):
    """A stiffening cell: closure 1e-6 (p / 1e-3)^0.7 (the scale of the scene's start law, k_n = 1000)."""
    return {"contact_fraction": min(1.0, float(np.sqrt(p / 2e-3))), "k_n0": 1.0, "g_n0": 0.0,
            "closure": 1e-6 * (p / 1e-3) ** 0.7}


def shear_response(load):
    """A cell that sticks, then slides at 0.3 p sqrt(1 + p / 1e-3): tau = that tanh(s / (0.5 p)), s = Delta 1e-4
    (odd in s; not exact along the rays s / p of the table's interpolation in p)."""
    p, d = load
    s = d * 1e-4
    return {"jump": s, "shear": 0.3 * p * float(np.sqrt(1 + p / 1e-3)) * float(np.tanh(s / (0.5 * p)))}


def analytic_tables(scene, tol: float = 0.05):
    from ngcontact.coupling import shear_table as ST
    from ngcontact.coupling import two_scale as T
    problem, _ = D.problem_of(scene, build_geometry(scene))
    table = PT.CellTable(normal_response, tol=tol)
    shear = ST.ShearTable(shear_response, tol=tol, length_unit=1e-4, max_solves=10 ** 5)
    solve = partial(D.solve_scene, scene)
    out = T.couple(problem, table, tol=1e-9, max_iter=20, table_min=1e-3, solve=solve, shear=shear,
                   points_per_element=scene.output.points_per_element)
    return out.solution, R.Relevel(scene, table, shear, solve)


def shear_reference(answer, relevel, scene, halvings: int = 3):
    """``answer`` solved again with both tables halved ``halvings`` times more where its interface uses them (the
    shear table in its pressures and in all jumps of its rows, :func:`~ngcontact.coupling.table_share.shear_loads`
    with ``whole``)."""
    from ngcontact.macro.macro_measures import interface_profile
    prof = interface_profile(answer, scene.output.points_per_element)
    fine = PT.CellTable(relevel.table.response, relevel.table.tol, values=dict(relevel.table.values))
    fine_shear = relevel.shear
    relevel.shear.max_solves = 10 ** 6                       # closed forms: the reference costs no cell solve
    for _ in range(halvings):
        fine = TS._finer(fine, dict(fine.values), prof["pressure"][prof["pressure"] > 0])
        fine_shear = TS.shear_finer(fine_shear, prof["pressure"], prof["jump_t"], keeper=relevel.shear, whole=True)
    law = il.InterfaceLaw(normal=PT.response_law(fine), friction=fine_shear.law())
    return D.solve_scene(scene, M.replace_law(answer.problem, law), answer.gfu.vec)


@pytest.mark.slow
def test_the_shear_tables_share_bounds_its_error_against_a_much_finer_table(tmp_path):
    """Effectivity of the two tables' share on a frictional block whose cell shear comes from a table: between
    1 and 10 on every quantity whose error against both tables halved three times more where the interface uses
    them is above round-off; the shear table's part is reported beside the pressure table's, and the tolerance
    had the shear table refined (its own first estimate misses the limit)."""
    scene = _friction_block(tmp_path)
    sol, relevel = analytic_tables(scene)
    answer = relevel.table_share(sol, 1e-3)
    share = relevel.share
    shear = ("shear_table_in_pressure", "shear_table_in_jump")
    assert share is not None and set(share.parts) == {"pressure_table", *shear}
    q = share.quantity()
    assert q["met"] and max(q["parts"][n]["share"] for n in shear) > q["parts"]["pressure_table"]["share"] > 0
    first = share.rounds[0]
    assert max(first["parts"][n]["share"] for n in shear) > share.limit / 3 and set(shear) & set(first["halved"])
    # one part refined a round, the largest, and estimated alone in the next: the others' estimates carried
    assert len(share.rounds) > 1 and all(len(r["halved"]) == 1 for r in share.rounds[:-1])
    for before, r in zip(share.rounds, share.rounds[1:]):
        (name,) = before["halved"]
        assert name == max(before["parts"], key=lambda n: before["parts"][n]["share"])
        assert [n for n, part in r["parts"].items() if not part.get("carried")] == [name]
    for name, e in share.shares.items():                     # the parts add
        assert e == pytest.approx(sum(share.parts[t][name] for t in share.parts), rel=1e-12)
    ref = shear_reference(answer, relevel, scene)
    component = next(k for k in share.values if k.startswith("resultant_")).removeprefix("resultant_")
    ref_q = measured(ref, relevel, scene, component)
    compared = []
    for name, value in share.values.items():
        true = abs(value - ref_q[name].value)
        if true <= 1e-9 * abs(ref_q[name].value):
            continue
        compared.append(name)
        assert true <= share.errors[name] <= 10 * true, (name, share.errors[name], true)
    assert len(compared) >= 3 and any(n.endswith("_away") for n in compared), compared


def test_the_safety_factor_is_a_quantity_of_the_share_and_bounded(tmp_path, monkeypatch):
    """With ``[strength]`` the safety factor of eq. 78 (linear recovery on the shipped hip-hills cell) is a
    headline quantity of the share, its estimate between 1 and 10 times its error against a much finer table
    (the press fit at twice its interference, where the stresses feel the table)."""
    import os
    from ngcontact.drivers.macro_accuracy import safety_factor_of
    from ngcontact.drivers.run_strength import recovery_of
    scene_with(tmp_path, monkeypatch, gap=-2e-3)
    path = tmp_path / "two_scale.toml"
    cell = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "cells", "hip_hills.toml"))
    path.write_text(path.read_text().replace("E = 200.0\n", "E = 200.0\nsigma_u = 1.0\n")
                    .replace("E = 70.0\n", "E = 70.0\nsigma_u = 0.5\n")
                    + f'\n[strength]\ncell = "{cell}"\ncriterion = "von_mises"\nrecovery = "linear"\n')
    scene = loader.load(path)
    sol, _, relevel = loop(scene, tmp_path)
    safety = safety_factor_of(scene, recovery_of(scene, sol.problem.law))
    assert safety is not None
    answer = relevel.table_share(sol, 1e-3, safety=safety)
    share = relevel.share
    assert share is not None and "safety_factor" in share.errors and share.share <= TS.FRACTION * 1e-3
    true = abs(share.values["safety_factor"] - safety(reference(answer, relevel.table, scene, 4)))
    assert true > 1e-9 * share.values["safety_factor"]
    assert true <= share.errors["safety_factor"] <= 10 * true, (share.errors["safety_factor"], true)
    assert share.values["safety_factor"] == pytest.approx(safety(answer), rel=1e-12)


def counted_shear_table(calls: list):
    """A shear table of :func:`shear_response` over p in [2e-4, 2e-3], s up to 5e-4, its cell loads in ``calls``."""
    from ngcontact.coupling import shear_table as ST

    def response(load):
        calls.append(load)
        return shear_response(load)
    table = ST.ShearTable(response, tol=0.05, length_unit=1e-4)
    table.cover(2e-4, 2e-3, 5e-4)
    return table


def test_the_shear_tables_held_loads_survive_the_cache_and_become_nodes_without_a_cell_solve(tmp_path):
    from ngcontact.coupling import shear_table as ST
    calls: list = []
    table = counted_shear_table(calls)
    nodes, solved = {p: dict(r) for p, r in table.rows.items()}, len(calls)
    p, s = np.array([5e-4, 1e-3, 1.5e-3]), np.array([1e-5, 2e-5, 3e-5])   # |s| / p small: the rows' first jumps
    assert len(TS.shear_loads(table, p, s)) < len(TS.shear_loads(table, p, s, whole=True)) / 2
    level = TS.shear_finer(table, p, s)
    added = {(q, d) for q, r in level.rows.items() for d in r} - {(q, d) for q, r in nodes.items() for d in r}
    assert table.rows == nodes and set(table.held) == {x for x in added if x[1] != 0.0}
    assert len(calls) == solved + len(table.held) and set(level.rows) > set(nodes)   # new rows at the middles
    R.store_shear("s" * 64, table, str(tmp_path))
    again, cached = R.cached_shear("s" * 64, table.response, 0.05, 1e-4, ST.serial_map, str(tmp_path))
    assert cached and again.rows == nodes and again.held == table.held
    rest = TS.whole_rows(again, set(level.rows) - set(again.rows))     # the new rows made whole when adopted
    assert rest and all(len(r) < len(nodes[max(nodes)]) for q, r in level.rows.items() if q not in nodes)
    assert TS.ShearPart(again, "pressure").adopt(level) == len(table.held) + len(set(rest) - table.held.keys())
    assert len(calls) == solved + len(table.held) + len(set(rest) - table.held.keys()) and not again.held
    assert all(again.rows[q][d] == v for q, r in level.rows.items() for d, v in r.items())   # held: not solved again
    P = np.array(sorted(nodes))
    for q in set(again.rows) - set(nodes):                                 # as far as a row beside it
        beside = P[max(int(np.searchsorted(P, q)) - 1, 0):int(np.searchsorted(P, q)) + 1]
        assert any(again.row(q)[0][-1] == pytest.approx(again.row(n)[0][-1] * q / n, rel=1e-12) for n in beside)


@pytest.mark.slow
def test_the_shear_share_of_an_fe_friction_cell_is_met_within_the_tables_bound(tmp_path):
    """The frictional block with its real FE cell (the sawtooth of ``scripts/sawtooth_shear.py``, micro Coulomb;
    cell solves in this process): the tolerance 5e-3 is met by the tables' share in its first round, within the
    shear table's bound on cell solves (halved in both directions at once and up to the interface's largest
    ``|s| / p``, that round alone passed the bound and the run ended with exit 3).  Each direction's halving asks
    for less than half the cells of the rows' whole halving, the share's two levels in both directions for less
    than twice them, and the share's rounds name both directions' parts."""
    from functools import partial as _partial
    from ngcontact.coupling import shear_table as ST
    from ngcontact.macro.macro_measures import interface_profile
    scene = _friction_block(tmp_path)
    problem, _ = D.problem_of(scene, build_geometry(scene))
    sol, _, relevel = R.couple_loop(scene, problem, _partial(D.solve_scene, scene), map_tasks=PT.serial_map,
                                    cache_dir=str(tmp_path / "cache"), shear_map=ST.serial_map)
    P = relevel.shear.pressures                 # no row again where the loop's range moved by round-off only
    assert np.min(np.diff(P) / P[1:]) > relevel.shear.tol / 10, P
    prof = interface_profile(sol, scene.output.points_per_element)
    whole = len(TS.shear_loads(relevel.shear, prof["pressure"], prof["jump_t"], whole=True))
    for direction in ("pressure", "jump"):
        assert 0 < len(TS.shear_loads(relevel.shear, prof["pressure"], prof["jump_t"], direction=direction)) < whole / 2
    before = relevel.shear.solves
    relevel.table_share(sol, 5e-3)
    share = relevel.share
    assert share is not None and share.share <= share.limit and len(share.rounds) == 1
    assert relevel.shear.solves <= relevel.shear.max_solves == scene.two_scale.max_cell_solves
    # the whole halving's first level alone asks for ``whole`` cells, its second (four times the rows' nodes)
    # for about three times that: the share's two levels in both directions for less than twice the first
    assert relevel.shear.solves - before < 2 * whole, (relevel.shear.solves - before, whole)
    assert {"shear_table_in_pressure", "shear_table_in_jump"} <= set(share.rounds[-1]["parts"])


def test_no_cell_load_of_the_shear_table_is_solved_twice_across_the_shares_rounds():
    """A round's second halving in pressure solves rows at the quarter points at the jumps of a neighbour carried
    along the rays; made nodes, the first midpoints carry their own (``d m / a``), and the next round's first
    halving carries those to the same quarter points (``(d m / a) q / m``): the same loads up to their last bits,
    which were solved again (21 cell solves on the FE friction block at 1e-3)."""
    calls: list = []
    table = counted_shear_table(calls)
    p = np.linspace(3e-4, 1.8e-3, 31)
    s = 2e-5 * np.sin(np.linspace(0.1, 3.0, 31))
    for _ in range(2):                                       # two rounds refining the pressure direction
        first = TS.shear_finer(table, p, s, direction="pressure")
        TS.shear_finer(first, p, s, keeper=table, direction="pressure")
        TS.ShearPart(table, "pressure").adopt(first)
    TS.shear_finer(TS.shear_finer(table, p, s, direction="pressure"), p, s, keeper=table, direction="pressure")
    by_row: dict = {}
    for q, d in calls:
        by_row.setdefault(q, []).append(d)
    twice = [(q, a, b) for q, ds in by_row.items() for a, b in zip(sorted(ds), sorted(ds)[1:])
             if b - a <= 1e-9 * abs(b)]
    assert len(calls) > 100 and not twice, twice[:3]
