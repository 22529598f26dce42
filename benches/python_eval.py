"""Value + gradient of one design model from Python, three ways, in one run.

1. the foldsynth package: ``model.value_and_grad(x, modes)`` (JIT code, GIL released);
2. the shared library of ``foldsynth compile`` called through ctypes (preallocated
   buffers; the gradient copied out of the reused buffer, as a caller must to keep it);
3. NumPy on the formulas of ``foldsynth model --formulas python``: the printed model has no
   gradient, so one vectorized call evaluates it at x and at x ± h·e_i (central
   differences, 2n+1 points in one batch: the fastest way those formulas give a gradient).

Each way runs for a fixed time per round; rounds are interleaved and the fastest round of
each counts (robust on a busy machine). The figures are ratios within this one run.

    .venv/bin/python benches/python_eval.py [--task grammar/gripper.toml]
        [--graph "2, 3, (4, 8), 4, (7, 8)"] [--modes up,down,up] [--rounds 7]
"""

import argparse
import ctypes
import importlib.util
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import foldsynth

ROOT = pathlib.Path(__file__).resolve().parents[1]


def cli_path(arg):
    if arg:
        return pathlib.Path(arg)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = target / "release" / "foldsynth"
    if not path.exists():
        sys.exit(f"no {path}: run `cargo build --release` first (or pass --cli)")
    return path


def per_call(fn, seconds):
    """Seconds per call of fn, calling it for about `seconds`."""
    n = 16
    while True:
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        dt = time.perf_counter() - t0
        if dt >= seconds:
            return dt / n
        n *= 2 if dt < seconds / 8 else max(2, int(seconds / dt) + 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default=str(ROOT / "grammar" / "gripper.toml"))
    ap.add_argument("--graph", default="2, 3, (4, 8), 4, (7, 8)")
    ap.add_argument("--modes", default="up,down,up")
    ap.add_argument("--candidate", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--seconds", type=float, default=0.2, help="per way and round")
    ap.add_argument("--cli", help="the foldsynth binary (default: target/release/foldsynth)")
    args = ap.parse_args()
    cli = cli_path(args.cli)
    common = [args.task, "--graph", args.graph, "--modes", args.modes,
              "--candidate", str(args.candidate)]

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        subprocess.run([str(cli), "compile", *common, "--emit", "so", "--name", "bench",
                        "--out", str(tmp)], check=True, capture_output=True)
        lib = ctypes.CDLL(str(tmp / "libbench.so"))
        formulas = subprocess.run([str(cli), "model", *common, "--formulas", "python"],
                                  check=True, capture_output=True, text=True).stdout
        (tmp / "bench_formulas.py").write_text(formulas)
        spec = importlib.util.spec_from_file_location("bench_formulas", tmp / "bench_formulas.py")
        printed = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(printed)

        task = foldsynth.Task.load(args.task)
        model = task.model(args.graph, candidate=args.candidate)
        n, m = model.n_vars, model.n_constraints
        modes = np.array([1.0 if s.strip() == "up" else -1.0 for s in args.modes.split(",")])
        params = np.concatenate([modes, model.times])
        lo, hi = model.bounds[:, 0], model.bounds[:, 1]
        x = lo + (hi - lo) * np.linspace(0.3, 0.7, n)

        # 1. the package
        def package():
            return model.value_and_grad(x, modes)

        # 2. the shared library through ctypes
        for fn in ("bench_n_vars", "bench_n_out", "bench_gradient_offset"):
            getattr(lib, fn).restype = ctypes.c_size_t
        assert lib.bench_n_vars() == n
        out = np.zeros(lib.bench_n_out())
        g0 = lib.bench_gradient_offset()
        ev = lib.bench_eval
        ev.argtypes = [ctypes.c_void_p] * 3
        ev.restype = None
        px, pp, po = x.ctypes.data, params.ctypes.data, out.ctypes.data

        def library():
            ev(px, pp, po)
            return out[0], out[g0:g0 + n].copy()

        # 3. NumPy on the printed formulas, central differences in one batch
        h = 1e-6
        steps = np.zeros((n, 2 * n + 1))
        for i in range(n):
            steps[i, 1 + 2 * i] = h
            steps[i, 2 + 2 * i] = -h
        plist = params.tolist()

        def numpy_path():
            f = printed.f(x[:, None] + steps, plist)[0]
            return f[0], (f[1::2] - f[2::2]) / (2 * h)

        # They compute the same thing.
        fp, gp = package()
        fl, gl = library()
        fn_, gn = numpy_path()
        assert fp == fl and np.array_equal(gp, gl), "package and library disagree"
        assert abs(fn_ - fp) <= 1e-12 * max(1.0, abs(fp)), (fn_, fp)
        assert np.allclose(gn, gp, rtol=1e-5, atol=1e-6), (gn, gp)

        ways = {"package": package, "library (ctypes)": library, "NumPy formulas": numpy_path}
        best = {k: float("inf") for k in ways}
        for _ in range(args.rounds):
            for k, fn in ways.items():
                best[k] = min(best[k], per_call(fn, args.seconds))

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"value + gradient of {args.graph} ({task.name}, candidate {args.candidate}, "
          f"modes {args.modes}): {n} variables, {m} constraints; "
          f"fastest of {args.rounds} interleaved rounds; load average {load:.1f} "
          f"on {os.cpu_count()} CPUs")
    for k, s in best.items():
        print(f"  {k:<18} {s * 1e6:10.2f} µs per call")
    speedup = best["NumPy formulas"] / best["package"]
    overhead = best["package"] / best["library (ctypes)"]
    print(f"  package vs NumPy formulas: {speedup:.0f}× faster (goal ≥ 50×: "
          f"{'met' if speedup >= 50 else 'NOT met'})")
    print(f"  package vs library (ctypes): {overhead:.2f}× the time (goal ≤ 2×: "
          f"{'met' if overhead <= 2 else 'NOT met'})")


if __name__ == "__main__":
    main()
