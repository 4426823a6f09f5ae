#!/usr/bin/env python3
"""Ruckig's one-axis time-optimal motion from any start state, both interfaces (the oracle of
crates/motion/tests/ruckig_state.rs).

stdin:  one case per line, "kind v0 a0 target v1 V A J n" with kind "p" (position interface:
        target position from 0, end speed v1) or "v" (velocity interface: target speed v1,
        target ignored); zero end acceleration; n samples. Blank lines ignored.
stdout: one line per case, "duration" then "p v a" at the n times duration·k/(n−1),
        k = 0 … n−1, as repr() floats; "nan" when Ruckig reports an error. One process.
`calculate` is shared with ruckig_batch.py.
"""
import sys

from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory


def calculate(otg, kind, v0, a0, target, v1, vmax, amax, jmax):
    """Ruckig's one-axis trajectory from (0, v0, a0): kind "p" to position `target` at speed
    v1, "v" to speed v1 (target ignored); zero end acceleration. None when Ruckig refuses."""
    inp = InputParameter(1)
    if kind == "v":
        inp.control_interface = ControlInterface.Velocity
    else:
        inp.target_position = [target]
    inp.current_position = [0.0]
    inp.current_velocity = [v0]
    inp.current_acceleration = [a0]
    inp.target_velocity = [v1]
    inp.target_acceleration = [0.0]
    inp.max_velocity = [vmax]
    inp.max_acceleration = [amax]
    inp.max_jerk = [jmax]
    traj = Trajectory(1)
    try:
        res = otg.calculate(inp, traj)
    except Exception:  # RuckigError on input it refuses
        return None
    return traj if res in (Result.Working, Result.Finished) else None


def main():
    otg = Ruckig(1)
    out = []
    for line in sys.stdin:
        f = line.split()
        if not f:
            continue
        v0, a0, target, v1, vmax, amax, jmax = map(float, f[1:8])
        n = int(f[8])
        traj = calculate(otg, f[0], v0, a0, target, v1, vmax, amax, jmax)
        if traj is None:
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
