#!/usr/bin/env python3
"""Instructions per frame by pipeline stage, counted by valgrind's callgrind (exactly repeatable).

Runs `plumb run` on N frames under `valgrind --tool=callgrind` (deterministic mode: one thread,
the stages in lock-step) and reads the inclusive instruction count (Ir) of each stage function
with callgrind_annotate. Whole-run counts divided by the number of frames:

  extract        FeatureExtractor::extract     (grey conversion + the three below + keypoint grid)
  extract.orb    OrbExtractor::extract         (pyramid, FAST, orientation, descriptors)
  extract.lines  LineExtractor::extract        (LSD on one pyramid level, LBD descriptors)
  extract.depth  DepthSampler::attachDepth     (depth per keypoint, line-guidance samples, 3D fits)
  track          OdometrySystem::trackFeatures (Tracker::track; relocalisation when lost)
  map            OdometrySystem::mapFrame      (keyframe insertion; counted over all frames)
  map.local_ba   LocalMapper::runLocalBa       (BA set-up, LM solve, covariances)
  loop           LoopStage::process            (loop closing per keyframe: place recognition,
                                                verification, pose graph; its own thread in the
                                                threaded modes, inline in deterministic mode)

and `total`, the sum of extract + track + map (a frame's work on the tracking path; the loop
stage is printed beside it, since it runs once per keyframe, off that path).

Scene set-up, image decoding/rendering and file output are not in any stage. Callgrind counts
the instructions the (simulated) CPU executes; OpenCV's runtime dispatch picks SIMD paths from
the CPU's features, so counts hold for one machine type (the budgets note which).

  instruction_counts.py --plumb build/bin/plumb [--dataset synth:fast_rotation:1:30] [--frames N]
                        [--check budgets.txt] [--keep-profile FILE]

With --check, each stage must stay within its budget (file format: `stage instructions_per_frame`
lines, `#` comments); exit 1 naming every stage over budget. Exit 77 (ctest: skipped) when
valgrind or callgrind_annotate is missing.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

STAGES = [
    ("extract", "plumb::FeatureExtractor::extract("),
    ("extract.orb", "plumb::OrbExtractor::extract("),
    ("extract.lines", "plumb::LineExtractor::extract("),
    ("extract.depth", "plumb::DepthSampler::attachDepth("),
    ("track", "plumb::OdometrySystem::trackFeatures("),
    ("map", "plumb::OdometrySystem::mapFrame("),
    ("map.local_ba", "plumb::LocalMapper::runLocalBa("),
    ("loop", "plumb::LoopStage::process("),
]
TOTAL = ("extract", "track", "map")

# "1,234,567 (12.34%)  file:function [object]"; the file part holds no colon ("???" without -g).
LINE = re.compile(r"^\s*([\d,]+)\s+\(\s*[\d.]+%\)\s+[^:\s]*:(.+?)(?:\s+\[[^\]]*\])?\s*$")


def inclusive_counts(profile):
    out = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", profile],
                         check=True, capture_output=True, text=True).stdout
    totals = {}
    for line in out.splitlines():
        m = LINE.match(line)
        if not m:
            continue
        count, function = int(m.group(1).replace(",", "")), m.group(2)
        for stage, prefix in STAGES:
            if function.startswith(prefix):
                # A function can appear once per object/file; the same symbol twice would be
                # an ODR surprise, so add rather than overwrite.
                totals[stage] = totals.get(stage, 0) + count
    return totals


def synth_flags(spec):
    """`plumb synth` flags for a source spec synth:PRESET[:SEED[:FRAMES]]."""
    parts = spec.split(":")[1:]
    flags = ["--preset", parts[0]]
    if len(parts) > 1:
        flags += ["--seed", parts[1]]
    if len(parts) > 2:
        flags += ["--frames", parts[2]]
    return flags


def read_budgets(path):
    budgets = {}
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            parts = line.split()
            if len(parts) != 2 or not parts[1].isdigit():
                sys.exit(f"{path}:{number}: expected 'stage instructions_per_frame', got {line!r}")
            budgets[parts[0]] = int(parts[1])
    unknown = set(budgets) - {s for s, _ in STAGES} - {"total"}
    if unknown:
        sys.exit(f"{path}: unknown stages {sorted(unknown)}")
    return budgets


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plumb", required=True)
    parser.add_argument("--dataset", default="synth:fast_rotation:1:30",
                        help="TUM folder, recording or synth:PRESET[:SEED[:FRAMES]] (rendered first)")
    parser.add_argument("--frames", type=int, default=0, help="--max-frames (0: the whole source)")
    parser.add_argument("--check", help="budget file: fail when a stage exceeds its budget")
    parser.add_argument("--keep-profile", help="also keep the callgrind output here")
    args = parser.parse_args()

    if not shutil.which("valgrind") or not shutil.which("callgrind_annotate"):
        print("instruction_counts: SKIPPED: valgrind/callgrind_annotate not installed "
              "(apt install valgrind; scripts/install_deps.sh lists it)")
        return 77

    with tempfile.TemporaryDirectory(prefix="plumb_instr_") as tmp:
        profile = args.keep_profile or os.path.join(tmp, "callgrind.out")
        trajectory = os.path.join(tmp, "trajectory.txt")
        dataset = args.dataset
        if dataset.startswith("synth:"):
            # Render the scene to a TUM folder first, outside valgrind: rendering costs ~3x the
            # whole pipeline per frame and is no stage; replaying PNGs is cheap.
            dataset = os.path.join(tmp, "scene")
            subprocess.run([args.plumb, "synth", "--out", dataset] + synth_flags(args.dataset),
                           check=True, capture_output=True)
        command = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={profile}",
                   args.plumb, "run", "--dataset", dataset, "--out", trajectory,
                   "--mode", "deterministic"]
        if args.frames > 0:
            command += ["--max-frames", str(args.frames)]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            print(run.stdout + run.stderr)
            sys.exit(f"instruction_counts: {' '.join(command)} failed ({run.returncode})")
        with open(trajectory) as f:
            frames = sum(1 for line in f if line.strip() and not line.startswith("# plumb"))
        totals = inclusive_counts(profile)

    if frames == 0:
        sys.exit("instruction_counts: the run wrote no frames")
    print(f"instructions per frame (callgrind Ir, inclusive), {frames} frames of {args.dataset}:")
    per_frame = {}
    for stage, prefix in STAGES:
        per_frame[stage] = totals.get(stage, 0) // frames
        print(f"  {stage:<14} {per_frame[stage]:>14,}   {prefix[:-1]}")
    per_frame["total"] = sum(per_frame[stage] for stage in TOTAL)
    print(f"  {'total':<14} {per_frame['total']:>14,}   {' + '.join(TOTAL)}")
    if not args.check:
        return 0

    budgets = read_budgets(args.check)
    failures = []
    for stage, budget in budgets.items():
        used = per_frame.get(stage, 0)
        verdict = "ok" if used <= budget else "OVER BUDGET"
        print(f"  budget {stage:<14} {used:>14,} / {budget:>14,} ({100.0 * used / budget:5.1f}%) {verdict}")
        if used > budget:
            failures.append(stage)
        if stage in ("extract", "track") and used == 0:
            failures.append(stage + " (not found in the profile: renamed function?)")
    if failures:
        print("instruction_counts: FAILED: over budget: " + ", ".join(failures))
        return 1
    print("instruction_counts: all stages within budget")
    return 0


if __name__ == "__main__":
    sys.exit(main())
