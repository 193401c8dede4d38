#!/usr/bin/env python3
"""What each loop correction did to the real-time output (docs/LOOP.md "`--out` with loops: what
is left").

Between two corrections the real-time trajectory (`plumb run --out`) is the no-loop trajectory
(`--no-loops --out`, same input) moved by ONE rigid motion D_k: a correction moves the local map
rigidly and tracking continues identically. This finds the corrections (frames where D changes),
then re-applies them in other ways and grades each variant's ATE with `plumb eval`:

  prefix k        the first k corrections, the k-th held to the end (k = 0 is the no-loop run)
  only piece k    D_k on its own piece, identity elsewhere (which correction costs what)
  share s         every D_k scaled by s (rotation about the query and translation), s < 1 =
                  a smaller real-time share K
  final graph     (with --optimized) at each correction the query goes to its FINAL optimised
                  pose moved into the frame of everything output before it (least-squares fit of
                  the optimised positions of the earlier frames onto their output positions): the
                  real-time anchor with the graph as it is at the end of the run

  plumb run --dataset synth:office_loop:2 --out rt.txt --out-optimized opt.txt
  plumb run --dataset synth:office_loop:2 --no-loops --out nl.txt
  scripts/realtime_corrections.py --plumb build/bin/plumb --gt synth:office_loop:2 \\
      --out rt.txt --no-loops nl.txt --optimized opt.txt

Python 3 standard library only.
"""
import argparse
import json
import math
import os
import subprocess
import tempfile


def load(path):
    poses = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            v = [float(x) for x in line.split()]
            poses[round(v[0], 4)] = (quat_to_r(v[4:8]), v[1:4])
    return poses


def quat_to_r(q):
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def r_to_quat(r):
    tr = r[0][0] + r[1][1] + r[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1) * 2
        return [(r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: r[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1 + r[i][i] - r[j][j] - r[k][k]) * 2
    q = [0.0] * 4
    q[i], q[j], q[k], q[3] = 0.25 * s, (r[j][i] + r[i][j]) / s, (r[k][i] + r[i][k]) / s, (r[k][j] - r[j][k]) / s
    return q


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def compose(a, b):
    ra, ta = a
    rb, tb = b
    return [[sum(ra[i][k] * rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)], \
        [x + y for x, y in zip(apply(ra, tb), ta)]


def inverse(a):
    rt = [list(c) for c in zip(*a[0])]
    return rt, [-x for x in apply(rt, a[1])]


def angle_deg(r):
    return math.degrees(math.acos(max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2))))


def log_r(r):
    th = math.radians(angle_deg(r))
    if th < 1e-12:
        return [0.0, 0.0, 0.0]
    k = th / (2 * math.sin(th))
    return [k * (r[2][1] - r[1][2]), k * (r[0][2] - r[2][0]), k * (r[1][0] - r[0][1])]


def exp_r(w):
    th = math.sqrt(sum(x * x for x in w))
    if th < 1e-15:
        return [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]
    k = [x / th for x in w]
    kx = [[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]]
    kx2 = [[sum(kx[i][m] * kx[m][j] for m in range(3)) for j in range(3)] for i in range(3)]
    return [[(i == j) + math.sin(th) * kx[i][j] + (1 - math.cos(th)) * kx2[i][j] for j in range(3)] for i in range(3)]


def jacobi_eigen4(a):
    a = [row[:] for row in a]
    v = [[float(i == j) for j in range(4)] for i in range(4)]
    for _ in range(100):
        if sum(a[i][j] ** 2 for i in range(4) for j in range(4) if i != j) < 1e-30:
            break
        for p in range(4):
            for q in range(p + 1, 4):
                if abs(a[p][q]) < 1e-300:
                    continue
                th = (a[q][q] - a[p][p]) / (2 * a[p][q])
                t = (1 if th >= 0 else -1) / (abs(th) + math.sqrt(th * th + 1))
                c = 1 / math.sqrt(t * t + 1)
                s = t * c
                for k in range(4):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
                for k in range(4):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
                for k in range(4):
                    vkp, vkq = v[k][p], v[k][q]
                    v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
    return [a[i][i] for i in range(4)], v


def rigid_fit(src, dst):
    """(R, t) minimising sum |R src + t - dst|^2 (Horn's quaternion method)."""
    n = len(src)
    ms = [sum(p[i] for p in src) / n for i in range(3)]
    md = [sum(q[i] for q in dst) / n for i in range(3)]
    s = [[0.0] * 3 for _ in range(3)]
    for p, q in zip(src, dst):
        for i in range(3):
            for j in range(3):
                s[i][j] += (p[i] - ms[i]) * (q[j] - md[j])
    (sxx, sxy, sxz), (syx, syy, syz), (szx, szy, szz) = s
    n4 = [[sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
          [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
          [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
          [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz]]
    values, vectors = jacobi_eigen4(n4)
    k = max(range(4), key=lambda i: values[i])
    w, x, y, z = [vectors[i][k] for i in range(4)]
    r = quat_to_r([x, y, z, w])
    return r, [md[i] - sum(r[i][j] * ms[j] for j in range(3)) for i in range(3)]


class Grader:
    def __init__(self, plumb, gt, stamps):
        self.plumb, self.gt, self.stamps = plumb, gt, stamps
        self.dir = tempfile.mkdtemp(prefix="rtcorr_")

    def ate(self, poses):
        path = os.path.join(self.dir, "est.txt")
        with open(path, "w") as f:
            for s in self.stamps:
                r, t = poses[s]
                f.write("%.6f %s %s\n" % (s, " ".join("%.10g" % v for v in t), " ".join("%.10g" % v for v in r_to_quat(r))))
        out = subprocess.run([self.plumb, "eval", "--gt", self.gt, "--est", path, "--json"], capture_output=True, text=True)
        return json.loads(out.stdout)["ate"]["rmse_m"]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--plumb", default="build/bin/plumb")
    p.add_argument("--gt", required=True, help="ground truth: a TUM file or synth:PRESET:SEED")
    p.add_argument("--out", required=True, help="plumb run --out (loops on)")
    p.add_argument("--no-loops", required=True, dest="noloops", help="plumb run --no-loops --out")
    p.add_argument("--optimized", default="", help="plumb run --out-optimized of the same run (optional)")
    p.add_argument("--min-step-mm", type=float, default=2.0, help="a correction: D changes by more than this ...")
    p.add_argument("--min-step-deg", type=float, default=0.05, help="... or this")
    args = p.parse_args()
    rt, nl = load(args.out), load(args.noloops)
    stamps = sorted(s for s in rt if s in nl)
    grader = Grader(args.plumb, args.gt, stamps)

    # D(t) = T_rt(t) T_nl(t)^-1; a correction where it steps. Each as rotation about the no-loop
    # query position q plus a translation there: p -> R (p - q) + q + dt.
    corrections = []  # (index, rotation vector, dt, q)
    previous = None
    for i, s in enumerate(stamps):
        d = compose(rt[s], inverse(nl[s]))
        q = nl[s][1]
        if previous is not None:
            step = compose(d, inverse(previous))
            moved = apply(step[0], q)
            step_mm = 1000 * math.dist([m + t for m, t in zip(moved, step[1])], q)
            if step_mm > args.min_step_mm or angle_deg(step[0]) > args.min_step_deg:
                at_q = [m + t - qq for m, t, qq in zip(apply(d[0], q), d[1], q)]
                corrections.append((i, log_r(d[0]), at_q, q))
                print(f"correction at frame {i} (t {s:.3f}): step {step_mm:.1f} mm, {angle_deg(step[0]):.3f} deg; "
                      f"D from the no-loop pose {1000 * math.sqrt(sum(v * v for v in at_q)):.1f} mm, "
                      f"{math.degrees(math.sqrt(sum(v * v for v in log_r(d[0])))):.3f} deg")
        previous = d

    def variant(which, share=1.0):
        poses = {}
        for i, s in enumerate(stamps):
            k = which(i)
            pose = nl[s]
            if k is not None:
                _, w, dt, q = corrections[k]
                r = exp_r([share * x for x in w])
                t = [q[m] + share * dt[m] - sum(r[m][n] * q[n] for n in range(3)) for m in range(3)]
                pose = compose((r, t), pose)
            poses[s] = pose
        return grader.ate(poses)

    def piece_of(i, allowed):
        k = None
        for j, c in enumerate(corrections):
            if i >= c[0] and j in allowed:
                k = j
        return k

    n = len(corrections)
    base = grader.ate(nl)
    print(f"no loops: ATE {base:.5f} m; --out: {grader.ate(rt):.5f} m ({grader.ate(rt) / base:.3f}x)")
    for k in range(1, n + 1):
        a = variant(lambda i: piece_of(i, set(range(k))))
        print(f"first {k} correction(s), the last held to the end: {a:.5f} m ({a / base:.3f}x)")
    for k in range(n):
        end = corrections[k + 1][0] if k + 1 < n else len(stamps)
        a = variant(lambda i: k if corrections[k][0] <= i < end else None)
        print(f"only piece {k + 1} (frames {corrections[k][0]}-{end - 1}) moved: {a:.5f} m ({a / base:.3f}x)")
    for share in (0.5, 0.75):
        a = variant(lambda i: piece_of(i, set(range(n))), share)
        print(f"every correction scaled by {share}: {a:.5f} m ({a / base:.3f}x)")
    if args.optimized:
        opt = load(args.optimized)
        poses, d = {}, None
        cut = {c[0] for c in corrections}
        for i, s in enumerate(stamps):
            if i in cut and s in opt:
                fit = rigid_fit([opt[stamps[j]][1] for j in range(i)], [poses[stamps[j]][1] for j in range(i)])
                d = compose(compose(fit, opt[s]), inverse(nl[s]))
            poses[s] = compose(d, nl[s]) if d is not None else nl[s]
        a = grader.ate(poses)
        print(f"each query at its FINAL optimised pose in the output's frame: {a:.5f} m ({a / base:.3f}x)")


if __name__ == "__main__":
    main()
