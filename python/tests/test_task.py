"""Tasks, graphs, the search and the vertex model through the package."""

import json
import math

import numpy as np

import foldsynth
from conftest import GRAPH


def test_enumerate_is_the_grammar(task):
    graphs = task.enumerate()
    # The library's enumeration test (tests/grammar_enumeration.rs): 53 meaningful graphs
    # and 1194 alternatives for the gripper at N_max = 3 (the thesis: 52 and 1170).
    assert len(graphs) == 53
    assert all(g.alternatives == 3 * 2 ** g.n_internal for g in graphs)
    assert sum(g.alternatives for g in graphs) == 1194
    assert all(1 <= g.n_internal <= 3 for g in graphs)
    assert len(task.enumerate(1)) < len(graphs)
    (g,) = [g for g in graphs if g.sequence == GRAPH]
    assert str(g) == GRAPH and g.n_internal == 3


def test_model_of_an_enumerated_graph_is_the_model_of_its_sequence(task, model):
    (g,) = [g for g in task.enumerate() if g.sequence == GRAPH]
    m = task.model(g)
    x = model.bounds.mean(axis=1)
    assert m.names == model.names
    assert m.value_and_grad(x, [1, 1, 1])[0] == model.value_and_grad(x, [1, 1, 1])[0]


def test_synthesize_streams_and_summarizes(task, tmp_path):
    out = tmp_path / "run"
    summary = task.synthesize(out=str(out), n_max=1, starts=4, export=False)
    graphs = task.enumerate(1)
    assert summary["graphs"] == len(graphs)
    assert summary["alternatives"] == sum(g.alternatives for g in graphs)
    assert summary["verification_failures"] == 0
    assert json.loads((out / "summary.json").read_text())["alternatives"] == summary["alternatives"]
    lines = (out / "alternatives.jsonl").read_text().splitlines()
    assert len(lines) == summary["alternatives"]


def test_vertex_is_the_ptu():
    spec = "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))"
    flat = foldsynth.vertex(spec, 0.0)
    assert flat["rigid"] and flat["closure"] < 1e-12
    assert flat["degree"] == 7 and flat["developable"] and flat["mode"] == "up"
    # U1 = 80°+40°+40° = 160°, U2 = 180°, U3 = 20° at t = 0 (sums of the units' sectors).
    np.testing.assert_allclose(flat["U"], np.radians([160.0, 180.0, 20.0]), atol=1e-12)
    ts = np.linspace(0.0, 1.0, 6)
    sweep = foldsynth.vertex(spec, ts)
    assert sweep["U"].shape == (6, 3) and sweep["rigid"].shape == (6,)
    # Wherever the vertex is rigid, folding it closes (the rotations compose to I).
    assert np.all(sweep["closure"][sweep["rigid"]] < 1e-12)
    one = foldsynth.vertex(spec, ts[3])
    np.testing.assert_array_equal(one["phi"], sweep["phi"][3])
    assert math.isclose(one["t"], ts[3])
