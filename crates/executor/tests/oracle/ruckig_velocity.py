#!/usr/bin/env python3
"""Ruckig's time-optimal velocity control for a batch of one-axis cases (the oracle of
crates/executor/tests/ruckig_velocity.rs).

stdin:  one case per line, "v0 a0 vt A J n": start speed and acceleration, target speed (reached
        at zero acceleration), limits, and a number of samples; blank lines ignored; start
        position 0.
stdout: one line per case, "duration" then "p v a" at the n times duration·k/(n−1),
        k = 0 … n−1, as repr() floats; "nan" when Ruckig reports an error. One process.
"""
import sys

from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory


def main():
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity
    traj = Trajectory(1)
    out = []
    for line in sys.stdin:
        f = line.split()
        if not f:
            continue
        v0, a0, vt, amax, jmax = map(float, f[:5])
        n = int(f[5])
        inp.current_position = [0.0]
        inp.current_velocity = [v0]
        inp.current_acceleration = [a0]
        inp.target_velocity = [vt]
        inp.target_acceleration = [0.0]
        inp.max_velocity = [1e12]
        inp.max_acceleration = [amax]
        inp.max_jerk = [jmax]
        try:
            res = otg.calculate(inp, traj)
        except Exception:
            res = None
        if res not in (Result.Working, Result.Finished):
            out.append("nan")
            continue
        d = traj.duration
        fields = [repr(d)]
        for k in range(n):
            t = d * k / (n - 1) if n > 1 else 0.0
            p, v, a = traj.at_time(t)
            fields += [repr(p[0]), repr(v[0]), repr(a[0])]
        out.append(" ".join(fields))
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
