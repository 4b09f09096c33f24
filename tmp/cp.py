import sys, math, numpy as np, animat
def lattice(nx, ny, jitter, seed):
    rng = np.random.default_rng(seed)
    p = np.array([(i + (0.5 if j % 2 else 0.0), j * math.sqrt(3) / 2) for j in range(ny) for i in range(nx)])
    return p + rng.uniform(-jitter, jitter, p.shape)
p = lattice(8, 4, 0.05, 8); n = len(p)
for f in (6.0, 12.0):
  for mode in ("breathe", "wave"):
    ph = np.zeros(n) if mode == "breathe" else (2*np.pi*p[:,0]/4.0) % (2*np.pi)
    b = animat.build_body(p, np.full(n, 0.2), np.full(n, f), ph)
    for cp in (100.0, 200.0, 300.0, 500.0):
        res=[]
        for dn in (0.2, 2.0, 10.0):
            for sub in (1, 16):
                c = animat.Config(); c["scene.pressure"]=cp; c["scene.drag_normal"]=dn; c["physics.substeps"]=sub
                r = animat.swim(b, config=c)
                res.append((r.distance, r.collisions, r.min_area_ratio))
        errs = [100*abs(res[2*k][0]-res[2*k+1][0])/max(res[2*k+1][0],1e-9) for k in range(3)]
        print(f"f={f} {mode} cp={cp}: coll {[res[2*k][1] for k in range(3)]} minS {[round(res[2*k][2],3) for k in range(3)]} fit {[round(res[2*k+1][0],2) for k in range(3)]} err% {[round(e,2) for e in errs]}", flush=True)
