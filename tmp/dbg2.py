import animat, numpy as np, sys
seed = int(sys.argv[1]); dn = float(sys.argv[2])
g = animat.Genome.random(animat.Rng.derive(20120707, seed))
c = animat.Config()
e = animat.develop(g, c); b = animat.build_body(e, c)
n = len(e.amplitude)
b2 = animat.build_body(np.asarray(b.positions), np.full(n, 0.2), np.full(n, 6.0), np.asarray(e.phase), c)
sc = animat.Scene(drag_normal=dn)
sim = animat.Simulation(b2, sc, c); sim.monitor_embedding(b2)
print("cells", n, "skin", np.asarray(b2.skin).shape, "regions", len(b2.regions))
prev = np.asarray(sim.positions).copy()
for k in range(4000):
    sim.step(1)
    em = sim.embedding
    if not em["intact"]:
        P = np.asarray(sim.positions)
        print("broken at", k, em, sim.counters)
        skin = np.asarray(b2.skin)
        def inter(p1,p2,p3,p4):
            def o(a,b,c): return (b[0]-a[0])*(c[1]-a[1])-(b[1]-a[1])*(c[0]-a[0])
            return o(p1,p2,p3)*o(p1,p2,p4) <= 0 and o(p3,p4,p1)*o(p3,p4,p2) <= 0
        for i in range(len(skin)):
            for j in range(i+1, len(skin)):
                a,bb = skin[i]; cc,d = skin[j]
                if len({a,bb,cc,d})<4: continue
                if inter(P[a],P[bb],P[cc],P[d]):
                    print("crossing", skin[i], skin[j]); 
                    for v in (a,bb,cc,d): print("  ", v, prev[v], "->", P[v])
        print("skin loops", [list(l) for l in b2.skin_loops])
        break
    prev = np.asarray(sim.positions).copy()
