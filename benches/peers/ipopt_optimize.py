"""IPOPT peer of `foldsynth bench optimize` (issue 33): the solver an engineer would reach
for, as the CasADi Python wheel ships it (IPOPT with MUMPS), on foldsynth's own models.

Usage: python3 ipopt_optimize.py JOB.json OUT.json

JOB.json (written by foldsynth): {"alternatives": [{"key", "formulas" (the model's
objective and constraints as `foldsynth model --formulas python` prints them, simplified
by egg), "params", "lo", "hi", "starts": [[x0…], …]}, …], "options": {…IPOPT options}}.
Each model's formulas are evaluated on CasADi SX symbols instead of NumPy arrays, so IPOPT
gets exact first and second derivatives by CasADi's automatic differentiation; every start
of every alternative is solved (foldsynth applies the search's stopping rule to the points
afterwards, judging them with its own compiled model). OUT.json: per alternative its
build time, the formulas' values at every start, and per start the point, IPOPT's status,
iterations, function-call counts and the CPU seconds of the solve.

Prints {"skipped": why} as its last line when CasADi is missing.
"""

import contextlib
import json
import math
import sys
import time
import types


def shim(ca):
    """The `np` the printed formulas call, on CasADi symbols."""
    return types.SimpleNamespace(
        sin=ca.sin,
        cos=ca.cos,
        sqrt=ca.sqrt,
        arctan2=ca.atan2,
        arccos=ca.acos,
        sign=ca.sign,
        clip=lambda x, lo, hi: ca.fmin(ca.fmax(x, lo), hi),
        where=lambda c, x, y: ca.if_else(c, x, y),
        errstate=lambda **_: contextlib.nullcontext(),
        pi=math.pi,
        inf=math.inf,
        nan=math.nan,
    )


def solve_alternative(ca, alt, options):
    glb = {"np": shim(ca)}
    # The printed module imports NumPy as np; here np is the shim.
    src = alt["formulas"].replace("import numpy as np", "")
    t0 = time.process_time()
    exec(compile(src, alt["key"], "exec"), glb)
    n = len(alt["lo"])
    x = ca.SX.sym("x", n)
    out = glb["f"]([x[i] for i in range(n)], alt["params"])
    f = out[0]
    g = ca.vertcat(*out[1:])
    solver = ca.nlpsol("s", "ipopt", {"x": x, "f": f, "g": g}, options)
    fg = ca.Function("fg", [x], [f, g])
    build_s = time.process_time() - t0
    m = g.shape[0]
    starts = []
    for x0 in alt["starts"]:
        t = time.process_time()
        r = solver(x0=x0, lbx=alt["lo"], ubx=alt["hi"], lbg=[0.0] * m, ubg=[math.inf] * m)
        cpu = time.process_time() - t
        st = solver.stats()
        calls = lambda name: int(st.get(f"n_call_{name}", 0))
        starts.append(
            {
                "x": [float(v) for v in r["x"].full().ravel()],
                "status": st.get("return_status", ""),
                "success": bool(st.get("success", False)),
                "iterations": int(st.get("iter_count", 0)),
                "f_calls": calls("nlp_f"),
                "g_calls": calls("nlp_g"),
                "grad_calls": calls("nlp_grad_f"),
                "jac_calls": calls("nlp_jac_g"),
                "hess_calls": calls("nlp_hess_l"),
                "cpu_s": cpu,
            }
        )
    # The formulas at every start, to check they are foldsynth's model.
    check = []
    for x0 in alt["starts"]:
        f0, g0 = fg(x0)
        check.append([float(f0)] + [float(v) for v in g0.full().ravel()])
    return {"key": alt["key"], "build_s": build_s, "at_starts": check, "starts": starts}


def main():
    try:
        import casadi as ca
    except ImportError as e:
        print(json.dumps({"skipped": f"no CasADi in this Python ({e}); pip install casadi"}))
        return
    job_path, out_path = sys.argv[1], sys.argv[2]
    with open(job_path, encoding="utf-8") as fh:
        job = json.load(fh)
    options = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes"}
    options.update({f"ipopt.{k}": v for k, v in job["options"].items()})
    results = [solve_alternative(ca, alt, options) for alt in job["alternatives"]]
    with open(out_path, "w", encoding="utf-8") as fh:
        json.dump({"casadi": ca.__version__, "alternatives": results}, fh)
    print(json.dumps({"done": len(results), "casadi": ca.__version__}))


if __name__ == "__main__":
    main()
