#!/usr/bin/env python3
"""CasADi peer for `foldsynth bench vertex --peer casadi`.

Builds the same function as foldsynth -- phi1 + phi2 + phi3 of one vertex by the PTU,
written exactly as foldsynth's kinematics writes it (src/kinematics/ptu.rs: the unit's
rotation chain as one 3x3 product whose first column and first row give P_jm and P'_j0;
atan2 forms of U, beta, delta; the half-angle form of the internal angles;
max0(x) = (x + x*sgn x)/2)
-- in CasADi SX, takes its reverse-mode gradient, generates C, compiles it with
`gcc -O3`, and times value+gradient in a C harness (batches, median).

Prints one JSON object on the last line of stdout. Exits 0 with {"skipped": ...} when
casadi or gcc is absent.

Usage: casadi_vertex.py [--vertex-json JSON] [--emit-harness DIR]
  --vertex-json   the vertex (default: the degree-7 benchmark vertex)
  --emit-harness  build the harness in DIR and print its command line ("harness")
                  instead of running it, so that the caller can alternate its own
                  measurements with the harness's (robust ratios on a busy machine)
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

DEFAULT = {
    "mode": 1.0,
    "units": [
        {"sectors_deg": [40, 50, 45, 35, 40], "driving": ["t", "-t", "t", "-t"]},
        {"sectors_deg": [55], "driving": []},
        {"sectors_deg": [95], "driving": []},
    ],
    "symbolic_sectors": True,
    "t": 1.0,
    "millis": 300,
}


def skip(why):
    print(json.dumps({"skipped": why}))
    sys.exit(0)


def ptu_phi_sum(ca, sectors, driving, mode):
    """sectors: per unit a list of SX; driving: per unit a list of SX; mode: SX."""
    sin, cos, atan2, sqrt, sign = ca.sin, ca.cos, ca.atan2, ca.sqrt, ca.sign

    def chain(sec, drv):
        # Q = R_z(a1) R_x(r1) ... R_x(r_{m-1}) R_z(a_m) as rows (src/kinematics/ptu.rs):
        # its first column is P_jm (Eq. 17), its first row P'_j0 (Eq. 21).
        m = len(sec)
        c, s = cos(sec[-1]), sin(sec[-1])
        q = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        for i in reversed(range(m - 1)):
            c, s = cos(drv[i]), sin(drv[i])
            r0, r1, r2 = q
            r1x = [c * r1[k] - s * r2[k] for k in range(3)]
            r2x = [s * r1[k] + c * r2[k] for k in range(3)]
            c, s = cos(sec[i]), sin(sec[i])
            r0z = [c * r0[k] - s * r1x[k] for k in range(3)]
            r1z = [s * r0[k] + c * r1x[k] for k in range(3)]
            q = [r0z, r1z, r2x]
        return q

    def unit_angles(sec, drv):
        if len(sec) == 1:
            return sec[0], 0, 0
        q = chain(sec, drv)
        x, r01, r02 = q[0]
        y, z = q[1][0], q[2][0]
        u = atan2(sqrt(y * y + z * z), x)
        beta = -atan2(z, y)
        delta = -atan2(r02, -r01)
        return u, beta, delta

    def max0(x):
        return (x + x * sign(x)) * 0.5

    a = [unit_angles(sectors[j], driving[j]) for j in range(3)]
    u = [a[j][0] for j in range(3)]
    beta = [a[j][1] for j in range(3)]
    delta = [a[j][2] for j in range(3)]
    s = (u[0] + u[1] + u[2]) * 0.5
    sin_s = sin(s)
    h = [sin(s - u[0]), sin(s - u[1]), sin(s - u[2])]

    def angle(i, j, k):
        num = sqrt(max0(h[j] * h[k]))
        den = sqrt(max0(sin_s * h[i]))
        return atan2(num, den) * 2.0

    theta = [angle(0, 1, 2), angle(1, 0, 2), angle(2, 0, 1)]
    turn = lambda th: mode * (math.pi - th)
    phi = [
        beta[2] + turn(theta[0]) + delta[1],
        beta[0] + turn(theta[1]) + delta[2],
        beta[1] + turn(theta[2]) + delta[0],
    ]
    return phi[0] + phi[1] + phi[2]


HARNESS = r"""
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "f.h"

static double now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e9 + ts.tv_nsec;
}

static int cmp(const void* a, const void* b) {
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

int main(int argc, char** argv) {
    int nx = atoi(argv[1]), np = atoi(argv[2]);
    double budget_ns = atof(argv[3]) * 1e6;
    double *x = malloc(sizeof(double) * (nx + 1)), *p = malloc(sizeof(double) * (np + 1));
    double fval, *grad = malloc(sizeof(double) * (nx + 1));
    for (int i = 0; i < nx; i++) x[i] = atof(argv[4 + i]);
    for (int i = 0; i < np; i++) p[i] = atof(argv[4 + nx + i]);
    casadi_int sz_arg, sz_res, sz_iw, sz_w;
    f_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
    const double** arg = malloc(sizeof(double*) * (sz_arg > 2 ? sz_arg : 2));
    double** res = malloc(sizeof(double*) * (sz_res > 2 ? sz_res : 2));
    casadi_int* iw = malloc(sizeof(casadi_int) * (sz_iw + 1));
    double* w = malloc(sizeof(double) * (sz_w + 1));
    arg[0] = x; arg[1] = p; res[0] = &fval; res[1] = grad;
    /* calibrate: a batch of ~1/20 of the budget */
    long n = 1;
    for (;;) {
        double t0 = now_ns();
        for (long k = 0; k < n; k++) f(arg, res, iw, w, 0);
        double e = now_ns() - t0;
        if (e > budget_ns / 80 || n > (1L << 30)) { n = (long)(n * (budget_ns / 20) / e) + 1; break; }
        n *= 4;
    }
    double s[41]; int m = 0; double start = now_ns();
    while (m < 5 || (now_ns() - start < budget_ns && m < 41)) {
        double t0 = now_ns();
        for (long k = 0; k < n; k++) f(arg, res, iw, w, 0);
        s[m++] = (now_ns() - t0) / n;
    }
    qsort(s, m, sizeof(double), cmp);
    /* JSON has no NaN: a non-finite value (CasADi's gradient outside the rigid interval)
       is written as null. */
    printf("{\"value_grad_ns\": %.3f, \"value\": ", s[m / 2]);
    if (isfinite(fval)) printf("%.17g", fval); else printf("null");
    printf(", \"grad\": [");
    for (int i = 0; i < nx; i++) {
        if (i) printf(", ");
        if (isfinite(grad[i])) printf("%.17g", grad[i]); else printf("null");
    }
    printf("]}\n");
    return 0;
}
"""


def main():
    desc = DEFAULT
    if "--vertex-json" in sys.argv:
        desc = json.loads(sys.argv[sys.argv.index("--vertex-json") + 1])
    try:
        import casadi as ca
    except ImportError:
        skip("casadi is not installed (pip install casadi)")
    gcc = shutil.which("gcc")
    if gcc is None:
        skip("gcc not found")

    t0 = time.perf_counter()
    units = desc["units"]
    degree = sum(len(u["sectors_deg"]) for u in units)
    sym = desc["symbolic_sectors"]
    if sym:
        x = ca.SX.sym("x", degree)
        p = ca.SX.sym("p", 2)
        t, mode = p[0], p[1]
        flat = [x[i] for i in range(degree)]
    else:
        x = ca.SX.sym("x", 1)
        p = ca.SX.sym("p", 1)
        t, mode = x[0], p[0]
        flat = [math.radians(a) for u in units for a in u["sectors_deg"]]
    sectors, driving, k = [], [], 0
    for u in units:
        m = len(u["sectors_deg"])
        sectors.append(flat[k : k + m])
        k += m
        # The driving angles are foldsynth's own printed expressions in t.
        driving.append([eval(d, {"__builtins__": {}}, {"t": t}) for d in u["driving"]])
    f = ptu_phi_sum(ca, sectors, driving, mode)
    g = ca.gradient(f, x)
    F = ca.Function("f", [x, p], [f, g])
    build_ms = (time.perf_counter() - t0) * 1e3

    emit = None
    if "--emit-harness" in sys.argv:
        emit = sys.argv[sys.argv.index("--emit-harness") + 1]
        os.makedirs(emit, exist_ok=True)
    tmp = emit or tempfile.mkdtemp(prefix="foldsynth-casadi-")
    try:
        t1 = time.perf_counter()
        cg = ca.CodeGenerator("f.c", {"with_header": True})
        cg.add(F)
        cg.generate(tmp + os.sep)
        codegen_ms = (time.perf_counter() - t1) * 1e3
        t2 = time.perf_counter()
        subprocess.run([gcc, "-O3", "-c", "f.c", "-o", "f.o"], cwd=tmp, check=True)
        gcc_ms = (time.perf_counter() - t2) * 1e3
        with open(os.path.join(tmp, "main.c"), "w") as fh:
            fh.write(HARNESS)
        subprocess.run(
            [gcc, "-O2", "main.c", "f.o", "-o", "bench", "-lm"], cwd=tmp, check=True
        )
        if sym:
            xs = [math.radians(a) for u in units for a in u["sectors_deg"]]
            ps = [desc["t"], desc["mode"]]
        else:
            xs = [desc["t"]]
            ps = [desc["mode"]]
        args = [os.path.join(tmp, "bench"), str(len(xs)), str(len(ps)), str(desc.get("millis", 300))]
        args += [repr(v) for v in xs + ps]
        if emit:
            r = {"harness": args}
        else:
            out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
    finally:
        if not emit:
            shutil.rmtree(tmp, ignore_errors=True)
    r.update(
        {
            "casadi_version": ca.__version__,
            "ops": F.n_instructions(),
            "casadi_build_ms": build_ms,
            "codegen_ms": codegen_ms,
            "gcc_ms": gcc_ms,
            "total_compile_ms": build_ms + codegen_ms + gcc_ms,
        }
    )
    print(json.dumps(r))


if __name__ == "__main__":
    main()
