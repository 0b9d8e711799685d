#!/usr/bin/env python3
"""Helpers of run.sh (Python 3 standard library only).

  bench_tools.py fit JNT LABEL H T_FROM    damped-sine fit of a deformable hinge's lag angle
                                           (MBDyn .jnt: column 16, the rotation vector's z, rad;
                                           one row per step from t = 0, step H s) from T_FROM s
  bench_tools.py time LOG DIR -- CMD ARGS...
                                           run CMD in DIR (output to /dev/null), append
                                           "user_s sys_s wall_s" of the process to LOG
  bench_tools.py report DIR STEPS SHORT_MBDYN SHORT_ROTORSIM
                                           the timing table of DIR/{mbdyn,rotorsim}{,_short}.times
"""
import math
import os
import statistics
import subprocess
import sys
import time


def solve(a, b):
    """Gaussian elimination with partial pivoting (small dense systems)."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        m[k], m[p] = m[p], m[k]
        for i in range(k + 1, n):
            f = m[i][k] / m[k][k]
            for j in range(k, n + 1):
                m[i][j] -= f * m[k][j]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))) / m[i][i]
    return x


def fit_damped_sine(x, h):
    """Least squares fit of x(t) = c + exp(-s t) (a cos(w t) + b sin(w t)), t = k h
    (Levenberg-Marquardt; start from the logarithmic decrement of the peaks).
    Returns (damped frequency [Hz], damping ratio s / sqrt(s^2 + w^2))."""
    c0 = sum(x) / len(x)
    peaks = [k for k in range(1, len(x) - 1) if x[k] - c0 > max(x[k - 1], x[k + 1]) - c0 > 0]
    if len(peaks) < 3:
        raise SystemExit("fit: fewer than three peaks in the lag history")
    n = len(peaks) - 1
    w = 2 * math.pi * n / ((peaks[-1] - peaks[0]) * h)
    s = math.log((x[peaks[0]] - c0) / (x[peaks[-1]] - c0)) / ((peaks[-1] - peaks[0]) * h)
    p = [c0, x[0] - c0, 0.0, s, w]

    def resid_jac(p):
        c, a, b, s, w = p
        r, j = [], []
        for k, v in enumerate(x):
            t = k * h
            e, cs, sn = math.exp(-s * t), math.cos(w * t), math.sin(w * t)
            y = e * (a * cs + b * sn)
            r.append(c + y - v)
            j.append([1.0, e * cs, e * sn, -t * y, t * e * (b * cs - a * sn)])
        return r, j

    lam = 1e-3
    r, j = resid_jac(p)
    cost = sum(v * v for v in r)
    for _ in range(200):
        jtj = [[sum(row[i] * row[k] for row in j) for k in range(5)] for i in range(5)]
        jtr = [sum(row[i] * rv for row, rv in zip(j, r)) for i in range(5)]
        a = [[jtj[i][k] * (1 + lam if i == k else 1) for k in range(5)] for i in range(5)]
        dp = solve(a, [-v for v in jtr])
        q = [pi + di for pi, di in zip(p, dp)]
        rq, jq = resid_jac(q)
        cq = sum(v * v for v in rq)
        if cq < cost:
            done = cost - cq <= 1e-14 * cost
            p, r, j, cost, lam = q, rq, jq, cq, lam / 10
            if done:
                break
        else:
            lam *= 10
            if lam > 1e12:
                break
    s, w = p[3], p[4]
    return w / (2 * math.pi), s / math.hypot(s, w)


def cmd_fit(jnt, label, h, t_from):
    lag = [float(f[15]) for f in (ln.split() for ln in open(jnt)) if f and f[0] == label]
    k0 = int(round(float(t_from) / float(h)))
    hz, zeta = fit_damped_sine(lag[k0:], float(h))
    print(f"{hz:.5f} {zeta:.6f} {len(lag)}")


def cmd_time(log, cwd, cmd):
    t0 = time.perf_counter()
    with open(os.devnull, "w") as null:
        proc = subprocess.Popen(cmd, cwd=cwd, stdout=null, stderr=null)
        _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise SystemExit(f"time: {cmd[0]} failed (status {status})")
    with open(log, "a") as f:
        f.write(f"{ru.ru_utime:.4f} {ru.ru_stime:.4f} {wall:.4f}\n")


def cmd_report(d, steps, short_m, short_r):
    steps, short_m, short_r = int(steps), int(short_m), int(short_r)

    def load(name):
        rows = [[float(v) for v in ln.split()] for ln in open(os.path.join(d, name + ".times"))]
        return [(u + s, wall) for u, s, wall in rows]

    m, r, m1, r1 = (load(n) for n in ("mbdyn", "rotorsim", "mbdyn_short", "rotorsim_short"))
    ms = lambda v, n: 1e3 * v / n  # noqa: E731  (s per run -> ms per step)
    print("CPU = user + sys of the whole process; stepping = (whole run - short run) / steps between")
    print(f"short runs: MBDyn {short_m} step(s), rotorsim {short_r} step(s); whole runs {steps} steps")
    head = ("pair", "MBDyn CPU", "rotorsim CPU", "CPU r/M", "MBDyn wall", "rotorsim wall",
            "wall r/M", "MBDyn step", "rotorsim step", "step r/M")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    cols = []
    for i in range(len(m)):
        sm = ms(m[i][0] - m1[i][0], steps - short_m)
        sr = ms(r[i][0] - r1[i][0], steps - short_r)
        row = [ms(m[i][0], steps), ms(r[i][0], steps), r[i][0] / m[i][0],
               ms(m[i][1], steps), ms(r[i][1], steps), r[i][1] / m[i][1], sm, sr, sr / sm]
        cols.append(row)
        print(f"| {i + 1} | " + " | ".join(f"{v:.3f}" for v in row) + " |")
    for name, f in (("median", statistics.median), ("min", min), ("max", max)):
        print(f"| {name} | " + " | ".join(f"{f(c):.3f}" for c in zip(*cols)) + " |")
    print("(ms per step of 5 ms; r/M = rotorsim / MBDyn)")


if __name__ == "__main__":
    a = sys.argv[1:]
    if a[:1] == ["fit"] and len(a) == 5:
        cmd_fit(*a[1:])
    elif a[:1] == ["time"] and len(a) > 4 and a[3] == "--":
        cmd_time(a[1], a[2], a[4:])
    elif a[:1] == ["report"] and len(a) == 5:
        cmd_report(*a[1:])
    else:
        raise SystemExit(__doc__)
