"""An animation of the best swimmer of a fresh run: GIF (or MP4 where ffmpeg is available).

PYTHONPATH=build/python .venv/bin/python examples/animate_swimmer.py [--run DIR] [--out swimmer.gif]
"""

import animat

from _common import fresh_run, parser

p = parser(__doc__, "swimmer.gif")
p.add_argument("--frames", type=int, default=160, help="frames (default 160)")
args = p.parse_args()
run = fresh_run(args)
trajectory = animat.replay(run.best(), run.config)
path = animat.animate(trajectory, args.out, fps=25, max_frames=args.frames, size=(480, 300))
print(f"wrote {path} ({trajectory.frame_count} frames recorded, distance {trajectory.distance:.3f})")
