"""The labels the undulation truth (known_swimmers.undulation_truth, at d_N = 0.5 and 2) gives every
whole-body candidate of the paper-kind sets, against the labels the sets record (TRUTH_REJECTED,
TRUTH_RELABELLED and each later set's own), so that a set is checked to be what its truth says without
the classifier.

    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/locomotion/truth_labels.py [sets]

prints, per candidate whose label by the truth differs from its built label (or that is rejected), the
truth at both drags, then per set the rejected and relabelled names and whether they match the record.
"""

import argparse
import warnings

import known_swimmers as K  # this folder (sys.path[0] when run as a script)

CANDIDATES = {
    "calibration": (K.calibration_candidates, K.TRUTH_RELABELLED, K.TRUTH_REJECTED),
    "held-out": (K.held_out_candidates, K.TRUTH_RELABELLED, K.TRUTH_REJECTED),
    "third": (K.third_set_candidates, K.TRUTH_RELABELLED, K.TRUTH_REJECTED),
    "fourth": (K.fourth_set_candidates, K.TRUTH_RELABELLED, K.TRUTH_REJECTED),
    "fifth": (K.fifth_set_candidates, K.FIFTH_RELABELLED, K.FIFTH_TRUTH_REJECTED),
    "sixth": (K.sixth_set_candidates, K.SIXTH_RELABELLED, K.SIXTH_TRUTH_REJECTED),
    "seventh": (K.seventh_set_candidates, K.SEVENTH_RELABELLED, K.SEVENTH_TRUTH_REJECTED),
    "eighth": (K.eighth_set_candidates, K.EIGHTH_RELABELLED, K.EIGHTH_TRUTH_REJECTED),
}


def _truth(u):
    if u is None:
        return "unstable"
    return f"{u.axis} lag {u.lag:.2f} coherence {u.coherence:.2f} swims {u.distance:.2f} at {u.axis_angle:.0f} deg" + (
        "" if u.undulates else f" ({u.why_not()})"
    )


def main(names):
    warnings.simplefilter("ignore")
    ok = True
    for name in names:
        build, relabelled, rejected = CANDIDATES[name]
        whole = [s for s in build() if not s.appendages and s.expected in K.WHOLE_BODY]
        found_rej, found_rel = [], {}
        for s, label, truths in K.label_by_truth(whole):
            if label is None:
                found_rej.append(s.name)
            elif label != s.expected:
                found_rel[s.name] = label
            if label != s.expected:
                print(f"{name} {s.name:26s} built {s.expected:24s} -> {label or 'rejected'}")
                for dn, u in zip((0.5, 2.0), truths):
                    print(f"    d_N = {dn:g}: {_truth(u)}")
        names_set = {s.name for s in whole}
        rec_rej = sorted(n for n in rejected if n in names_set)
        rec_rel = {n: v for n, v in relabelled.items() if n in names_set}
        match = sorted(found_rej) == rec_rej and found_rel == rec_rel
        ok &= match
        print(
            f"{name}: {len(whole)} whole-body candidates, rejected {sorted(found_rej)}, relabelled {found_rel}"
            f" -> {'matches the record' if match else 'DIFFERS from the record'}"
        )
    return ok


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sets", nargs="?", default=",".join(CANDIDATES), help="comma-separated: " + ", ".join(CANDIDATES))
    raise SystemExit(0 if main(ap.parse_args().sets.split(",")) else 1)
