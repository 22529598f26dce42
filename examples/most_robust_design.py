"""Search, pick the most robust design, plot its tip path and save its FOLD file.

    python examples/most_robust_design.py [TASK] [--n-max N] [--out DIR]

(from the repository's root: TASK defaults to grammar/gripper.toml). Writes, in DIR
(default out/example):
  the run itself (summary.json, alternatives.jsonl, designs/…, report.html),
  tip_path.png   the gripping vertex's path over the motion (matplotlib, where installed),
  tip_path.csv   the same path as numbers (t, x, y, z),
  best.fold      the most robust design as FOLD 1.2 (Origami Simulator, the FOLD tools).
"""

import argparse
import csv
import pathlib

import foldsynth


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("task", nargs="?", default="grammar/gripper.toml")
    ap.add_argument("--n-max", type=int, default=None, help="default: the task's N_max")
    ap.add_argument("--out", default="out/example")
    args = ap.parse_args()
    out = pathlib.Path(args.out)

    # The search; force=True replaces an earlier run of other settings in `out`.
    run = foldsynth.synthesize(args.task, out=out / "run", n_max=args.n_max, force=True, export=False)
    designs = run.designs()  # most robust first
    print(f"{run.summary['alternatives']} alternatives, {len(designs)} designs")
    if len(designs) == 0:
        raise SystemExit("no design: try a larger --n-max")

    best = run.design(1)
    print(f"most robust: {best.id} ({best.sequence}, modes {','.join(best.modes)}), "
          f"score {best.robustness['score']:.3g}, Ω* = {best.objective:.3g}")

    # The tip (gripping vertex) over the motion: an (F, 3) array, one row per state.
    t, tip = best.frames.t, best.tip_path
    with open(out / "tip_path.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "x", "y", "z"])
        w.writerows([[ti, *p] for ti, p in zip(t, tip)])
    try:
        import matplotlib

        matplotlib.use("Agg")  # files, no window
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: the path is in", out / "tip_path.csv")
    else:
        fig = plt.figure(figsize=(5, 4))
        ax = fig.add_subplot(projection="3d")
        ax.plot(*tip.T, marker=".")
        ax.scatter(*tip[-1], color="red", label=f"t = {t[-1]:.3g}")
        ax.set(xlabel="x", ylabel="y", zlabel="z", title=f"tip of {best.id}")
        ax.legend()
        fig.savefig(out / "tip_path.png", dpi=100)
        print("plot:", out / "tip_path.png")

    print("FOLD:", best.save_fold(out / "best.fold"))


if __name__ == "__main__":
    main()
