#!/usr/bin/env python3
"""Ruckig's one-axis time-optimal duration for a batch of forward moves (the oracle of
crates/motion/tests/ruckig_oracle.rs).

stdin:  one case per line, "L v0 v1 V A J [n]" (distance, start and end speed, limits, and
        optionally a number of samples), blank lines ignored; zero acceleration at both ends,
        start position 0, target position L.
stdout: one line per case, "duration vmin end": Ruckig's optimal duration, the lowest speed
        along its trajectory (negative = it drives backward) and the position where it ends
        (L up to Ruckig's tolerance, ~1e-8 absolute), as repr() floats; "nan nan nan" when
        Ruckig reports an error. With n samples, the line goes on with "p v a" at the n times
        duration·k/(n−1), k = 0 … n−1. One process for the whole batch.
"""
import sys

from ruckig import Ruckig

from ruckig_state import calculate


def min_speed(traj):
    """Lowest velocity over the 7 constant-jerk phases, at phase ends or where a = 0 inside."""
    prof = traj.profiles[0][0]
    t, j, a, v = list(prof.t), list(prof.j), list(prof.a), list(prof.v)
    vmin = v[0]
    for k in range(7):
        if t[k] <= 0.0:
            continue  # a skipped phase's knot values are not meaningful
        vmin = min(vmin, v[k + 1])
        if j[k] != 0.0:
            tau = -a[k] / j[k]
            if 0.0 < tau < t[k]:
                vmin = min(vmin, v[k] + a[k] * tau + 0.5 * j[k] * tau * tau)
    return vmin


def main():
    otg = Ruckig(1)
    out = []
    for line in sys.stdin:
        f = line.split()
        if not f:
            continue
        dist, v0, v1, vmax, amax, jmax = map(float, f[:6])
        samples = int(f[6]) if len(f) > 6 else 0
        traj = calculate(otg, "p", v0, 0.0, dist, v1, vmax, amax, jmax)
        if traj is None:
            out.append("nan nan nan")
            continue
        end = traj.at_time(traj.duration)[0][0]
        fields = [traj.duration, min_speed(traj), end]
        for k in range(samples):
            p, v, a = traj.at_time(traj.duration * k / (samples - 1))
            fields += [p[0], v[0], a[0]]
        out.append(" ".join(repr(x) for x in fields))
    sys.stdout.write("\n".join(out))
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
