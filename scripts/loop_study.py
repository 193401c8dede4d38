#!/usr/bin/env python3
"""Loop closing study: does loop closing ever make a trajectory worse? (docs/LOOP.md "Study")

For every sequence it can run -- each synthetic preset x seeds x {noise-free, Kinect-like noise},
and the TUM folders that are present (head250, desk9) -- it runs `plumb run` twice, with loop
closing (default) and with --no-loops, evaluates the ATE of --out (real time) and --out-optimized
against ground truth (`plumb eval`), grades the loop audit (`plumb eval --loops`), and prints one
Markdown table with a verdict per row:

  opt <= 1.02 x no-loops   (issue 20: --out-optimized never worse by more than 2 %)
  rt  <= 1.05 x no-loops   (--out never worse by more than 5 %)
  every accepted loop correct (<= 5 cm, <= 2 deg, within 3 sigma: plumb eval --loops)

Results are cached per run in --work (a rerun only runs what is missing), so the table can be
rebuilt cheaply and a study interrupted on a loaded machine resumes where it stopped.

  scripts/loop_study.py --plumb build/bin/plumb --work /tmp/loop_study --jobs 2 > table.md
  scripts/loop_study.py ... --presets office_loop,office_pass --seeds 1,2,3 --noise both

Python 3 standard library only.
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

PRESETS = ["textured", "low_texture", "fast_rotation", "loop", "repeated", "office_loop", "office_pass"]
LOOPED_PRESETS = {"loop", "office_loop"}  # their paths revisit: recall is graded over these
TUM = {"head250": "tum_fr1_rpy_head250", "desk9": "tum_fr1_desk_first9"}


def run(cmd, log):
    with open(log, "w") as f:
        return subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode


def json_of(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        return None
    try:
        return json.loads(out.stdout)
    except json.JSONDecodeError:
        return None


class Sequence:
    def __init__(self, name, dataset, gt, extra, looped):
        self.name, self.dataset, self.gt, self.extra, self.looped = name, dataset, gt, extra, looped


def sequences(args):
    seqs = []
    noises = {"off": [False], "on": [True], "both": [False, True]}[args.noise]
    for preset in args.presets:
        for seed in args.seeds:
            for noise in noises:
                spec = f"synth:{preset}:{seed}"
                name = f"{preset}:{seed}{' noise' if noise else ''}"
                seqs.append(Sequence(name, spec, spec, ["--synth-noise"] if noise else [], preset in LOOPED_PRESETS))
    for short, folder in TUM.items():
        if short not in args.tum:
            continue
        path = os.path.join(args.datasets, folder)
        if os.path.isdir(path):
            seqs.append(Sequence(short, path, os.path.join(path, "groundtruth.txt"), ["--camera", "tum1"], True))
        else:
            print(f"<!-- {short}: {path} not found, skipped -->", file=sys.stderr)
    return seqs


def key(seq):
    return seq.name.replace(":", "_").replace(" ", "_")


def do_runs(args, seq):
    base = os.path.join(args.work, key(seq))
    loops_ok = os.path.exists(base + ".loops.done")
    if not loops_ok:
        rc = run([args.plumb, "run", "--dataset", seq.dataset, "--out", base + ".rt.txt", "--out-optimized",
                  base + ".opt.txt", "--stats", base + ".stats.json"] + seq.extra, base + ".loops.log")
        if rc == 0:
            open(base + ".loops.done", "w").close()
    if not os.path.exists(base + ".noloops.done") and args.noloops_from:
        # --no-loops writes the same bytes with any build that did not change the odometry (check
        # with cmp before relying on it): reuse another study's run.
        other = os.path.join(args.noloops_from, key(seq))
        if os.path.exists(other + ".noloops.done"):
            with open(other + ".noloops.txt", "rb") as src, open(base + ".noloops.txt", "wb") as dst:
                dst.write(src.read())
            open(base + ".noloops.done", "w").close()
    if not os.path.exists(base + ".noloops.done"):
        rc = run([args.plumb, "run", "--dataset", seq.dataset, "--out", base + ".noloops.txt", "--no-loops"] + seq.extra,
                 base + ".noloops.log")
        if rc == 0:
            open(base + ".noloops.done", "w").close()
    return seq


def ate(args, gt, est):
    j = json_of([args.plumb, "eval", "--gt", gt, "--est", est, "--json"])
    return j["ate"]["rmse_m"] if j else None


def evaluate(args, seq):
    base = os.path.join(args.work, key(seq))
    row = {"name": seq.name, "looped": seq.looped}
    if not (os.path.exists(base + ".loops.done") and os.path.exists(base + ".noloops.done")):
        row["error"] = "run failed (see " + base + ".*.log)"
        return row
    row["noloops"] = ate(args, seq.gt, base + ".noloops.txt")
    row["rt"] = ate(args, seq.gt, base + ".rt.txt")
    row["opt"] = ate(args, seq.gt, base + ".opt.txt")
    grading = json_of([args.plumb, "eval", "--gt", seq.gt, "--loops", base + ".stats.json", "--json"])
    if grading:
        row.update({k: grading.get(k, 0) for k in ("accepted", "graded", "correct", "within_5cm_2deg", "revisits",
                                                   "revisits_recalled")})
        # NEES of each graded loop constraint: error_sigmas^2 = e^T S^-1 e (6 dof).
        graded = [l for l in grading.get("loops", []) if l.get("ground_truth") and l.get("error_sigmas") is not None]
        row["nees"] = [l["error_sigmas"] ** 2 for l in graded]
        # (true baseline between the two views [m], NEES, error [m]) per loop: the table by baseline.
        row["by_baseline"] = [(l.get("baseline_m", 0.0), l["error_sigmas"] ** 2, l["error_m"]) for l in graded]
    with open(base + ".stats.json") as f:
        stats = json.load(f)
    lc = stats.get("loop_closing", {})
    row["rejected"] = lc.get("loops_rejected", {})
    return row


def fmt(x, digits=4):
    return "-" if x is None else f"{x:.{digits}f}"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--plumb", default="build/bin/plumb")
    p.add_argument("--work", default="/tmp/plumb_loop_study")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--presets", default=",".join(PRESETS))
    p.add_argument("--seeds", default="1,2,3,4,5")
    p.add_argument("--noise", choices=["off", "on", "both"], default="both")
    p.add_argument("--tum", default="head250,desk9", help="TUM folders to include (comma list, '' for none)")
    p.add_argument("--datasets", default="../shared/datasets")
    p.add_argument("--noloops-from", default="", help="reuse the --no-loops runs of another --work folder")
    p.add_argument("--evaluate-only", action="store_true", help="run nothing: the table of the runs finished so far")
    args = p.parse_args()
    args.presets = [x for x in args.presets.split(",") if x]
    args.seeds = [int(x) for x in args.seeds.split(",") if x]
    args.tum = [x for x in args.tum.split(",") if x]
    os.makedirs(args.work, exist_ok=True)
    seqs = sequences(args)
    if not args.evaluate_only:
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            for seq in pool.map(lambda s: do_runs(args, s), seqs):
                print(f"done {seq.name}", file=sys.stderr)
    if args.evaluate_only:  # only what finished
        seqs = [s for s in seqs if os.path.exists(os.path.join(args.work, key(s)) + ".loops.done")
                and os.path.exists(os.path.join(args.work, key(s)) + ".noloops.done")]
    rows = [evaluate(args, s) for s in seqs]

    print("| sequence | no loops ATE [m] | `--out` ATE [m] | `--out` / no loops | `--out-optimized` ATE [m] | "
          "opt / no loops | loops accepted / correct (within 5 cm, 2 deg) | loop NEES/dof (max) | revisits recalled | verdict |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    totals = {"rows": 0, "fail_rt": 0, "fail_opt": 0, "accepted": 0, "correct": 0, "revisits": 0, "recalled": 0}
    all_nees = []
    all_by_baseline = []  # (family, baseline, NEES, error)
    for r in rows:
        if "error" in r or r.get("noloops") is None or r.get("rt") is None or r.get("opt") is None:
            print(f"| {r['name']} | {r.get('error', 'evaluation failed')} | | | | | | | | |")
            continue
        totals["rows"] += 1
        rt_ratio, opt_ratio = r["rt"] / r["noloops"], r["opt"] / r["noloops"]
        accepted, correct = r.get("accepted", 0), r.get("correct", 0)
        verdict = []
        if opt_ratio > 1.02:
            verdict.append("opt > 2 %")
            totals["fail_opt"] += 1
        if rt_ratio > 1.05:
            verdict.append("rt > 5 %")
            totals["fail_rt"] += 1
        if correct < r.get("graded", 0):
            far = r["graded"] - r.get("within_5cm_2deg", 0)
            verdict.append(f"{r['graded'] - correct} wrong loop(s)" +
                           (f" ({far} beyond 5 cm / 2 deg)" if far else " (within 5 cm / 2 deg, beyond 3 sigma)"))
        totals["accepted"] += r.get("graded", 0)
        totals["correct"] += correct
        nees = r.get("nees", [])
        all_nees += nees
        family = r["name"].split(":")[0] + (" noise" if r["name"].endswith(" noise") else "")
        all_by_baseline += [(family,) + x for x in r.get("by_baseline", [])]
        nees_cell = f"{sum(nees) / len(nees) / 6:.2f} ({max(nees) / 6:.2f})" if nees else "-"
        recall = "-"
        if r["looped"] and r.get("revisits"):
            totals["revisits"] += r["revisits"]
            totals["recalled"] += r["revisits_recalled"]
            recall = f"{r['revisits_recalled']}/{r['revisits']}"
        print(f"| {r['name']} | {fmt(r['noloops'])} | {fmt(r['rt'])} | {rt_ratio:.3f} | {fmt(r['opt'])} | "
              f"{opt_ratio:.3f} | {accepted} / {correct} ({r.get('within_5cm_2deg', 0)}) | {nees_cell} | {recall} | {'ok' if not verdict else ', '.join(verdict)} |")
    precision = 100.0 * totals["correct"] / totals["accepted"] if totals["accepted"] else 100.0
    recall = 100.0 * totals["recalled"] / totals["revisits"] if totals["revisits"] else float("nan")
    print()
    print(f"{totals['rows']} sequences: `--out-optimized` worse than no loops by > 2 % on {totals['fail_opt']}, "
          f"`--out` worse by > 5 % on {totals['fail_rt']}; loop precision {precision:.1f} % "
          f"({totals['correct']} of {totals['accepted']}); recall {recall:.1f} % of the revisits of the looped "
          f"sequences ({totals['recalled']} of {totals['revisits']}).")
    if all_nees:
        inside = sum(1 for x in all_nees if x <= 12.59)  # 6-dof chi-square, 95 %
        print(f"Loop constraints: mean NEES/dof {sum(all_nees) / len(all_nees) / 6:.2f} over {len(all_nees)} "
              f"accepted loops, {100.0 * inside / len(all_nees):.0f} % inside the 95 % ellipsoid.")
    if all_by_baseline:
        # A loop's error grows with how far apart its two views are (docs/LOOP.md "Loop error
        # against baseline"): the calibration must hold in every bin, not only on average.
        print()
        print("| family | views apart | loops | mean NEES/dof | median error [mm] |")
        print("|---|---|---|---|---|")
        bins = [(0.0, 0.25), (0.25, 0.5), (0.5, 1.0), (1.0, float("inf"))]
        for family in sorted({x[0] for x in all_by_baseline}):
            for lo, hi in bins:
                cell = [x for x in all_by_baseline if x[0] == family and lo <= x[1] < hi]
                if not cell:
                    continue
                errors = sorted(x[3] for x in cell)
                span = f"{lo:g}-{hi:g} m" if hi != float("inf") else f">= {lo:g} m"
                print(f"| {family} | {span} | {len(cell)} | {sum(x[2] for x in cell) / len(cell) / 6:.2f} | "
                      f"{1000 * errors[len(errors) // 2]:.1f} |")


if __name__ == "__main__":
    main()
