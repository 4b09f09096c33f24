"""Cost of one evaluation of an adversarial genome at a given size (docs/reliability.md, "worst case").

    PYTHONPATH=build/python .venv/bin/python fuzz/worst_case_genome.py UNITS GENE_TYPE

UNITS promoter+gene units (2*UNITS + 10 elements) with every point within the affinity cut-off of
every other, so the GRN is as dense as it gets; GENE_TYPE 1 = internal genes, 2 = morphogen genes.
"""
import sys, time, resource, numpy as np, animat
n_units = int(sys.argv[1]); gene = int(sys.argv[2])  # 1 internal, 2 morphogen
types = []; chans = []
for c in range(4): types.append(3); chans.append(c)
for u in range(n_units): types += [0, gene]; chans += [0, 0]
for c in range(6): types.append(4); chans.append(c)
n = len(types)
coords = np.full((n, 2), 5.0) + np.random.default_rng(1).uniform(0, 0.5, (n, 2))
g = animat.Genome.from_arrays(np.array(types), np.ones(n, dtype=np.int64), np.array(chans), coords)
c = animat.Config(); c["genome.max_elements"] = max(10000, n)
t = time.time()
r = animat.evaluate(g, c)
print(f"{n} elements ({'morphogen' if gene == 2 else 'internal'} genes): {time.time()-t:.1f} s, viable={r.viable}, cells={r.cell_count}, dev steps={r.development_steps}, peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss/1024:.0f} MB")
