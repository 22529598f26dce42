"""The compiled design model on NumPy arrays: scipy reaches the gripper's target, values
equal the CLI's, gradients equal central differences, bad arguments raise clearly."""

import json
import math
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from scipy.optimize import minimize

import foldsynth
from conftest import GRAPH, ROOT

MODES = np.array([1.0, -1.0, 1.0])


def points(model, count, seed):
    """Points spread over the model's bounds, off the bounds themselves."""
    rng = np.random.default_rng(seed)
    lo, hi = model.bounds[:, 0], model.bounds[:, 1]
    return [lo + (hi - lo) * (0.05 + 0.9 * rng.random(model.n_vars)) for _ in range(count)]


def test_names_bounds_sizes(model):
    assert model.n_vars == len(model.names) == model.bounds.shape[0]
    assert model.bounds.shape == (model.n_vars, 2)
    assert np.all(model.bounds[:, 0] < model.bounds[:, 1])
    assert model.n_modes == 3
    assert len(model.constraint_labels) == model.n_constraints
    # Sector angles are bounded by [α_min, α_max] = [π/18, 17π/18], lengths by [0.1, 1.5].
    for name, (lo, hi) in zip(model.names, model.bounds):
        if name.startswith("α"):
            assert (lo, hi) == (math.pi / 18, 17 * math.pi / 18)
        else:
            assert (lo, hi) == (0.1, 1.5)
    assert model.times[0] == math.pi / 2


def test_scipy_slsqp_reaches_the_gripper_target(model):
    """SLSQP with the compiled gradient and the constraints' Jacobian finds a design whose
    gripping vertex is at P_G = (0, 0, 1) at t = π/2 (Ω ≤ 1e-5) with every ψ satisfied."""
    modes = MODES
    cons = {
        "type": "ineq",
        "fun": lambda x: model.constraints_and_jacobian(x, modes)[0],
        "jac": lambda x: model.constraints_and_jacobian(x, modes)[1],
    }
    best = None
    for x0 in points(model, 12, seed=1):
        res = minimize(
            model.value_and_grad,
            x0,
            args=(modes,),
            jac=True,
            method="SLSQP",
            bounds=model.bounds,
            constraints=[cons],
            options={"maxiter": 300, "ftol": 1e-16},
        )
        g, _ = model.constraints_and_jacobian(res.x, modes)
        if res.fun <= model.objective_target and g.min() >= -1e-9:
            best = res
            break
    assert best is not None, "no start reached the target"
    # Ω from the plain f64 kinematics, independent of the compiled model.
    assert model.omega(best.x, modes) <= model.threshold


def test_values_equal_the_cli(model, cli, tmp_path):
    """`foldsynth model --at VARS.json --json` evaluates the same compiled function."""
    for k, x in enumerate(points(model, 3, seed=2)):
        at = tmp_path / f"x{k}.json"
        at.write_text(json.dumps(dict(zip(model.names, x.tolist()))))
        out = subprocess.run(
            [str(cli), "model", str(ROOT / "grammar" / "gripper.toml"), "--graph", GRAPH,
             "--modes", "up,down,up", "--at", str(at), "--json", "--sweep", "2"],
            capture_output=True, text=True, check=True,
        )
        report = json.loads(out.stdout)
        assert [v["value"] for v in report["variables"]] == x.tolist()
        f, _ = model.value_and_grad(x, MODES)
        g, _ = model.constraints_and_jacobian(x, ["up", "down", "up"])
        assert f == report["objective_compiled"]
        assert g.tolist() == [c["value"] for c in report["constraints"]]
        assert model.omega(x, "up,down,up") == report["objective"]


def test_gradient_and_jacobian_match_central_differences(model):
    h = 1e-6
    for x in points(model, 3, seed=3):
        f, df = model.value_and_grad(x, MODES)
        g, jac = model.constraints_and_jacobian(x, MODES)
        assert jac.shape == (model.n_constraints, model.n_vars)
        for i in range(model.n_vars):
            e = np.zeros(model.n_vars)
            e[i] = h
            fp, _ = model.value_and_grad(x + e, MODES)
            fm, _ = model.value_and_grad(x - e, MODES)
            gp, _ = model.constraints_and_jacobian(x + e, MODES)
            gm, _ = model.constraints_and_jacobian(x - e, MODES)
            assert abs((fp - fm) / (2 * h) - df[i]) <= 1e-6 * (1 + abs(df[i]))
            np.testing.assert_allclose((gp - gm) / (2 * h), jac[:, i], rtol=1e-6, atol=1e-6)


def test_evaluate_is_both_halves(model):
    x = points(model, 1, seed=4)[0]
    f, g, df, jac = model.evaluate(x, MODES)
    f2, df2 = model.value_and_grad(x, MODES)
    g2, jac2 = model.constraints_and_jacobian(x, MODES)
    assert f == f2 and np.array_equal(df, df2)
    assert np.array_equal(g, g2) and np.array_equal(jac, jac2)


def test_times_are_parameters(model):
    """At t = 0 the paper is flat: the gripping vertex lies in the xy-plane, so its squared
    distance from P_G = (0, 0, 1) is |xy|² + 1 ≥ 1; at the default t = π/2 it can be 0."""
    x = points(model, 1, seed=5)[0]
    f0, _ = model.value_and_grad(x, MODES, t=0.0)
    assert f0 >= 1.0
    f_default, _ = model.value_and_grad(x, MODES)
    f_half, _ = model.value_and_grad(x, MODES, t=np.array([math.pi / 2]))
    assert f_default == f_half


def test_threads_agree(model):
    """The GIL is released during evaluation; concurrent calls give the serial results."""
    xs = points(model, 64, seed=6)
    serial = [model.value_and_grad(x, MODES)[0] for x in xs]
    with ThreadPoolExecutor(4) as pool:
        parallel = list(pool.map(lambda x: model.value_and_grad(x, MODES)[0], xs))
    assert serial == parallel


def test_optimize_meets_the_target(model):
    r = model.optimize(modes=MODES, starts=16, seed=0)
    assert r["met_target"] and r["feasible"]
    assert r["omega"] <= model.threshold
    f, _ = model.value_and_grad(r["x"], MODES)
    assert f == r["objective"]


def test_bad_arguments_raise_clear_errors(task, model):
    x = points(model, 1, seed=7)[0]
    with pytest.raises(ValueError, match=r"x has 9 entries; this model has 10 variables \(α_3"):
        model.value_and_grad(x[:9], MODES)
    bad = x.copy()
    bad[2] = np.nan
    with pytest.raises(ValueError, match=r"x\[2\] \(α_4\) is NaN"):
        model.value_and_grad(bad, MODES)
    with pytest.raises(ValueError, match=r"modes: 2 were given; give 3 modes"):
        model.value_and_grad(x, [1, 1])
    with pytest.raises(ValueError, match=r"modes\[1\] is 0.5"):
        model.value_and_grad(x, [1, 0.5, 1])
    with pytest.raises(ValueError, match=r"'sideways' is not a mode"):
        model.constraints_and_jacobian(x, "up,sideways,up")
    with pytest.raises(ValueError, match=r"t has 2 entries; this model folds at 1 values"):
        model.value_and_grad(x, MODES, t=[0.1, 0.2])
    with pytest.raises(TypeError, match=r"x: expected a 1-D array of numbers"):
        model.value_and_grad({"a": 1}, MODES)
    with pytest.raises(ValueError, match=r"x: expected a 1-D array of numbers, got shape \(2, 5\)"):
        model.value_and_grad(np.zeros((2, 5)), MODES)
    with pytest.raises(foldsynth.FoldsynthError, match=r"graph '2, 9, 9'"):
        task.model("2, 9, 9")
    with pytest.raises(ValueError, match=r"candidate must be 1, 2 or 3"):
        task.model(GRAPH, candidate=4)
    with pytest.raises(TypeError, match=r"graph: expected a Graph or a rule sequence"):
        task.model(42)
    with pytest.raises(foldsynth.FoldsynthError, match=r"missing\.toml"):
        foldsynth.Task.load(str(ROOT / "grammar" / "missing.toml"))
    with pytest.raises(foldsynth.FoldsynthError, match=r"invalid vertex"):
        foldsynth.vertex("v(up, ((80,40", 0.5)
    with pytest.raises(ValueError, match=r"n_max must be at least 1"):
        task.enumerate(0)
    # FoldsynthError is a ValueError.
    assert issubclass(foldsynth.FoldsynthError, ValueError)
