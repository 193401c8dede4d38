#!/usr/bin/env python3
"""Footprint of the `plumb` binary: shared libraries, resident memory, time to the first pose.

  python3 scripts/footprint.py [--plumb build/bin/plumb] [--dataset ../shared/datasets/tum_fr1_rpy_head250]
                               [--repeat 7]

Prints (targets of issue 14, docs/EMBEDDED.md):
  shared libraries      `ldd plumb | wc -l`
  --help peak RSS       ru_maxrss of `plumb --help`                                   (<= 16 MiB)
  run peak RSS          ru_maxrss of `plumb run --dataset D --out T` (whole sequence) (<= 48 MiB)
  first pose            `plumb run --max-frames 1 --output-delay 0` from process start to exit,
                        when the one pose is in the file: wall (min and median of --repeat runs)
                        and the process's CPU time (user + sys; what a loaded machine cannot
                        inflate)                                                       (<= 50 ms)
Peak RSS and CPU time come from /usr/bin/time (GNU time: %M, %U + %S; apt install time).
The dataset lines are skipped when the folder is absent; synth:textured needs no data.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

MIB = 1024.0


def run_child(command):
    """Runs command under /usr/bin/time; returns (exit code, wall s, cpu s, peak RSS KiB).

    Not os.wait4() from here: Linux carries a process's RSS high-water mark across exec, so a
    child forked from this Python interpreter would report Python's resident set too."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as report:
        start = time.perf_counter()
        code = subprocess.run(["/usr/bin/time", "-f", "%M %U %S", "-o", report.name] + command,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
        wall = time.perf_counter() - start
        fields = report.read().split()[-3:]
    return code, wall, float(fields[1]) + float(fields[2]), int(fields[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plumb", default="build/bin/plumb")
    parser.add_argument("--dataset", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared",
                                                          "datasets", "tum_fr1_rpy_head250"))
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()

    libraries = subprocess.run(["ldd", args.plumb], capture_output=True, text=True, check=True).stdout
    print(f"shared libraries (ldd | wc -l)  {len(libraries.strip().splitlines())}")

    helps = [run_child([args.plumb, "--help"])[3] for _ in range(3)]
    print(f"--help peak RSS                 {max(helps) / MIB:6.1f} MiB (target <= 16)")

    sources = ["synth:textured"]
    if os.path.isdir(args.dataset):
        sources.insert(0, os.path.normpath(args.dataset))
    else:
        print(f"({args.dataset} absent: real-data lines skipped)")
    failed = False
    with tempfile.TemporaryDirectory(prefix="plumb_footprint_") as tmp:
        out = os.path.join(tmp, "trajectory.txt")
        for source in sources:
            code, wall, cpu, rss = run_child([args.plumb, "run", "--dataset", source, "--out", out])
            failed |= code != 0
            target = " (target <= 48)" if not source.startswith("synth:") else ""
            print(f"run peak RSS  {source}: {rss / MIB:6.1f} MiB{target}  [{wall:.1f} s wall, exit {code}]")
        for source in sources:
            walls, cpus = [], []
            for _ in range(args.repeat):
                code, wall, cpu, _ = run_child([args.plumb, "run", "--dataset", source, "--out", out,
                                                "--max-frames", "1", "--output-delay", "0"])
                failed |= code != 0
                walls.append(wall * 1e3)
                cpus.append(cpu * 1e3)
            print(f"first pose    {source}: wall min {min(walls):6.1f} ms, median {statistics.median(walls):6.1f} ms;"
                  f" CPU min {min(cpus):6.1f} ms (target <= 50)")
    with open("/proc/loadavg") as f:
        print(f"load average while measuring: {' '.join(f.read().split()[:3])} "
              f"({os.cpu_count()} CPUs; wall times grow with load, CPU times much less)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
