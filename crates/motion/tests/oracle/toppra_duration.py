#!/usr/bin/env python3
"""TOPP-RA's time-optimal duration of one path under joint velocity and acceleration limits
and a path-speed (feed) limit: the oracle of crates/motion/tests/toppra_oracle.rs.

stdin:  line 1 "n": the number of joints;
        line 2 "V1 .. Vn A1 .. An": joint velocity and acceleration limits (mm/s, mm/s²);
        then one waypoint per line, "s feed q1 .. qn": the path coordinate (arc length, mm,
        strictly increasing), the feed limit on ds/dt there (mm/s; a huge value for none),
        and the joints.
stdout: "duration gridpoints", with repr() floats; "nan 0" when TOPP-RA fails.

The path is the cubic spline through the waypoints (scipy, through toppra's
SplineInterpolator), parametrised by s. The feed is a velocity limit on one more "joint"
equal to s, varying along the path (JointVelocityConstraintVarying). Jerk is not limited, so
this duration bounds every jerk-limited plan of the same path from below (up to the grid).
"""
import sys

import numpy as np
import toppra as ta
import toppra.algorithm as algo
import toppra.constraint as constraint


def main():
    lines = [l.split() for l in sys.stdin if l.strip()]
    n = int(lines[0][0])
    lim = list(map(float, lines[1]))
    vmax, amax = np.array(lim[:n]), np.array(lim[n:2 * n])
    rows = np.array([list(map(float, l)) for l in lines[2:]])
    s, feed, q = rows[:, 0], rows[:, 1], rows[:, 2:]
    # To metres, from the run's start: seidel's LP tolerances are absolute, and in mm (speeds
    # of 10², accelerations of 10³) fine grids fail as "not controllable". Times are unchanged.
    s, feed, q = (s - s[0]) / 1000.0, feed / 1000.0, q / 1000.0
    vmax, amax = vmax / 1000.0, amax / 1000.0
    # The extra coordinate is s itself: its speed is the path speed.
    path = ta.SplineInterpolator(s, np.column_stack([q, s]))
    vlim_const = np.concatenate([vmax, [np.inf]])

    def vlim(x):
        f = float(np.interp(x, s, feed))
        hi = np.concatenate([vlim_const[:n], [f]])
        return np.column_stack([-hi, hi])

    # |s̈| = |T·q̈| ≤ ‖q̈‖ ≤ ‖A‖ on mill3 (q = tip): a limit on the extra coordinate's
    # acceleration that never binds; a huge one (1e12) leaves seidel's LPs badly conditioned.
    alim = np.concatenate([amax, [1.01 * float(np.linalg.norm(amax))]])
    vel = constraint.JointVelocityConstraintVarying(vlim)
    acc = constraint.JointAccelerationConstraint(np.column_stack([-alim, alim]))
    grid = min(20000, max(1000, 4 * len(s)))
    inst = algo.TOPPRA([vel, acc], path, gridpoints=np.linspace(s[0], s[-1], grid),
                       parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0, 0)
    if traj is None:
        print("nan 0")
    else:
        print(repr(float(traj.duration)), grid)


if __name__ == "__main__":
    main()
