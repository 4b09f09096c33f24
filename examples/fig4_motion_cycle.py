"""Paper Figs. 4-6: one motion cycle of the best swimmer of a fresh run, nodes red (expanding),
blue (contracting) or green (neutral) from eq. 2, rotated so that it swims to the right.

    PYTHONPATH=build/python .venv/bin/python examples/fig4_motion_cycle.py [--run DIR] [--out PNG]
"""

import animat

from _common import fresh_run, parser, save_png

args = parser(__doc__, "motion_cycle.png").parse_args()
run = fresh_run(args)
best = run.best()
trajectory = animat.replay(best, run.config)  # the evaluation again, every step recorded
print(trajectory)
fig = animat.plot.motion_cycle(trajectory, count=6)  # 6 snapshots over the last oscillation period
save_png(fig, args.out)
