"""Confusion matrices of animat.classify_locomotion with the paper's stroke rule on the hand-built
swimmers of known_swimmers.py (paper_calibration_set, paper_held_out_set, paper_third_set,
paper_fourth_set, paper_fifth_set, paper_sixth_set and paper_seventh_set, all now calibration, and the
eighth held-out set paper_eighth_set;
2000 steps at d_N = 0.5 and 2), every label from the ground truths (stroke_truth, undulation_truth).

    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/confusion.py calibration,held-out,third
    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/confusion.py fourth,fifth
    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/confusion.py sixth
    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/confusion.py seventh
    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/confusion.py eighth

prints one line per swim (distance, label (by the ground truths) and found mode, the stroke's pair score and area, and for
the appendage swimmers the ground truth of known_swimmers.stroke_truth) and the matrix (rows: labelled undulation, synchronous contraction, protrusions, tail, other; columns: the same,
then none, unstable).
"""

import argparse
import warnings

import known_swimmers as K  # this folder (sys.path[0] when run as a script)

CLASSES = ["undulation", "synchronous contraction", "protrusions", "tail", "other"]
SETS = {
    "calibration": K.paper_calibration_set,
    "held-out": K.paper_held_out_set,
    "third": K.paper_third_set,
    "fourth": K.paper_fourth_set,
    "fifth": K.paper_fifth_set,
    "sixth": K.paper_sixth_set,
    "seventh": K.paper_seventh_set,
    "eighth": K.paper_eighth_set,
}


def main(names):
    warnings.simplefilter("ignore")
    for name in names:
        res = K.classify_known(SETS[name](), drags=(0.5, 2.0), steps=2000, stroke_rule=True)
        for r in res:
            st = r.mode.stroke if r.mode is not None else None
            sc = (
                f"pair score {st.score:+.2f}, area {st.area:.3f}, {len(st.protrusions)} protrusions, "
                f"{len(st.pairs)} pairs"
                if st is not None
                else "-"
            )
            truth = ""
            u = r.undulation
            if u is not None:
                truth = f"; undulation truth {'undulates' if u.undulates else 'does not: ' + u.why_not()}"
            if r.truth is not None:
                truth = f"; ground truth {'strokes' if r.truth.strokes else 'does not stroke: ' + r.truth.why_not()}"
                truth += f" (rowing {min(r.truth.rowing):+.2f})"
            print(
                f"{name} {r.swimmer.name:28s} dN={r.drag_normal:g} distance={r.distance:6.2f} "
                f"label={r.swimmer.expected:24s} found={r.mode.label if r.mode else 'unstable':32s} {sc}{truth}"
            )
        print(name)
        print(K.confusion_matrix(res, CLASSES, CLASSES + ["none", "unstable"]))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "sets",
        nargs="?",
        default=",".join(SETS),
        help="comma-separated sets to swim: " + ", ".join(SETS) + " (default: all)",
    )
    names = ap.parse_args().sets.split(",")
    unknown = [n for n in names if n not in SETS]
    if unknown:
        ap.error(f"unknown set(s) {', '.join(unknown)}; choose from {', '.join(SETS)}")
    main(names)
