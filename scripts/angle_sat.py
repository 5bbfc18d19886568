#!/usr/bin/env python3
"""Reference angles of a red-green leaf mesh as a SAT problem (docs/IMPORT.md, "Reference angles by
a SAT solver, measured"). Reads what bench/angle_labels writes (the leaf mesh, base valences and the
true labels), checks that the truth satisfies the constraints, writes a CNF, solves it with the
cadical executable, compares the labelling with the truth and, with --unique, solves again with
that labelling excluded. An experiment (cadical is Debian's `cadical` package, no dependency of amcodec):

    build/bench/angle_labels --random 8 r8.txt      # seed 8 of tests/import_leaf_test.cpp's random hierarchies
    scripts/angle_sat.py r8.txt --extra vlevels,ends,corner --unique

prints the CNF's size, the solver's answers and times, and how many faces differ from the truth."""
import argparse
import os
import random
import subprocess
import sys
import time
from collections import defaultdict

# Corner angles in units of 30 degrees, every base triangle equilateral: a red triangle, the
# (1, 2, 3) halves of bisections and closures in their 6 corner orders, the closure's (1, 1, 4) in 3.
LABELS = [(2, 2, 2), (1, 2, 3), (1, 3, 2), (2, 1, 3), (2, 3, 1), (3, 1, 2), (3, 2, 1), (4, 1, 1), (1, 4, 1),
          (1, 1, 4)]
RED = 0
L0, L1, D = 0, 1, 2  # the side opposite a corner: L_k, L_{k+1} or the green diagonal D_k


def side_type(label, corner):
    if label == RED:
        return L0
    return {1: L1, 2: D, 3: L0, 4: D}[LABELS[label][corner]]


def read_labels(path):
    with open(path) as f:
        assert f.readline().split()[0] == "angle-labels"
        nv, nf, nb, depth = map(int, f.readline().split())
        valence = [int(f.readline()) for _ in range(nb)]
        faces, truth, level, root = [], [], [], []
        for _ in range(nf):
            a, b, c, x, y, z, k, r = map(int, f.readline().split())
            faces.append((a, b, c))
            truth.append(LABELS.index((x, y, z)))
            level.append(k)
            root.append(r)
    return nv, faces, valence, depth, truth, level, root


class Mesh:
    def __init__(self, nv, faces):
        self.nv = nv
        self.faces = faces
        self.half = {}  # (u, v) -> (face, side): side i of a face is the edge opposite its corner i
        for f, t in enumerate(faces):
            for i in range(3):
                self.half[(t[(i + 1) % 3], t[(i + 2) % 3])] = (f, i)
        self.edges = []  # (f, i, g, j) for interior edges, (f, i, -1, -1) for boundary ones
        self.boundary_vertices = set()
        for (u, v), (f, i) in self.half.items():
            twin = self.half.get((v, u))
            if twin is None:
                self.edges.append((f, i, -1, -1))
                self.boundary_vertices.update((u, v))
            elif u < v:
                self.edges.append((f, i) + twin)
        self.corners = defaultdict(list)
        for f, t in enumerate(faces):
            for i in range(3):
                self.corners[t[i]].append((f, i))
        # Each vertex's fan in order: corners c_0 .. c_{n-1}, edges[j] before c_j (n + 1 of them on the
        # boundary, where the first and last are boundary edges; n around an interior vertex).
        self.fans = {}
        for v, cs in self.corners.items():
            start = cs[0]
            for f, i in cs:
                if (v, faces[f][(i + 1) % 3]) not in self.half or (faces[f][(i + 1) % 3], v) not in self.half:
                    start = (f, i)  # no face before this corner: the open fan starts here
            fan, edges = [], []
            f, i = start
            while True:
                fan.append((f, i))
                edges.append(edge_key(v, faces[f][(i + 1) % 3]))
                w = faces[f][(i + 2) % 3]
                nxt = self.half.get((v, w))
                if nxt is None:
                    edges.append(edge_key(v, w))
                    break
                f, i = nxt[0], (nxt[1] + 1) % 3
                if (f, i) == start:
                    break
            assert len(fan) == len(cs), "non-manifold vertex %d" % v
            self.fans[v] = (fan, edges)


def edge_key(u, v):
    return (u, v) if u < v else (v, u)


def true_flags(mesh, root):
    """Leaf edges on base edges: between faces of two base triangles, or on the boundary."""
    return {edge_key(mesh.faces[f][(i + 1) % 3], mesh.faces[f][(i + 2) % 3])
            for f, i, g, j in mesh.edges if g < 0 or root[f] != root[g]}


def check_chains(mesh, valence, labels, flags):
    bad = []
    for v, (fan, edges) in mesh.fans.items():
        sep = 2 if v < len(valence) else 6
        at = [k for k, e in enumerate(edges) if e in flags]
        if not at:
            if v < len(valence):
                bad.append(("base vertex without base edge", v))
            continue
        cyclic = len(edges) == len(fan)
        angles = [LABELS[labels[f]][i] for f, i in fan]
        pairs = list(zip(at, at[1:])) + ([(at[-1], at[0] + len(fan))] if cyclic else [])
        for x, y in pairs:
            if sum(angles[k % len(fan)] for k in range(x, y)) != sep:
                bad.append(("separation", v))
    return bad


def target_sum(mesh, valence, v):
    if v < len(valence):
        return 2 * valence[v]
    return 6 if v in mesh.boundary_vertices else 12


def check_truth(mesh, valence, truth, level):
    bad = []
    for v, cs in mesh.corners.items():
        s = sum(LABELS[truth[f]][i] for f, i in cs)
        if s != target_sum(mesh, valence, v):
            bad.append(("angle sum", v, s))
    for f, i, g, j in mesh.edges:
        tf = side_type(truth[f], i)
        if g < 0:
            if tf == D:
                bad.append(("boundary D", f))
            continue
        tg = side_type(truth[g], j)
        if (tf == D) != (tg == D):
            bad.append(("D once", f, g))
            continue
        lf = level[f] + (tf == L1)
        lg = level[g] + (tg == L1)
        if lf != lg:
            bad.append(("length", f, g, lf, lg))
    return bad


class Cnf:
    def __init__(self):
        self.n = 0
        self.clauses = []

    def var(self, count=1):
        first = self.n + 1
        self.n += count
        return first

    def add(self, *lits):
        self.clauses.append(lits)


def build(mesh, valence, levels, extra):
    cnf = Cnf()
    nf = len(mesh.faces)
    x = [cnf.var(10) for _ in range(nf)]  # x[f] + l: face f has label l
    a = [cnf.var(12) for _ in range(nf)]  # a[f] + 4 i + (angle - 1)
    t = [cnf.var(9) for _ in range(nf)]  # t[f] + 3 i + type
    ge = [cnf.var(levels) for _ in range(nf)]  # ge[f] + k - 1: level of f >= k, k = 1 .. levels
    for f in range(nf):
        cnf.add(*[x[f] + l for l in range(10)])
        for l in range(10):
            for m in range(l + 1, 10):
                cnf.add(-(x[f] + l), -(x[f] + m))
        for i in range(3):
            for angle in range(1, 5):
                with_it = [l for l in range(10) if LABELS[l][i] == angle]
                for l in with_it:
                    cnf.add(-(x[f] + l), a[f] + 4 * i + angle - 1)
                cnf.add(-(a[f] + 4 * i + angle - 1), *[x[f] + l for l in with_it])
            for ty in range(3):
                with_it = [l for l in range(10) if side_type(l, i) == ty]
                for l in with_it:
                    cnf.add(-(x[f] + l), t[f] + 3 * i + ty)
                cnf.add(-(t[f] + 3 * i + ty), *[x[f] + l for l in with_it])
        for k in range(1, levels):
            cnf.add(-(ge[f] + k), ge[f] + k - 1)  # >= k+1 implies >= k

    def ge_lit(f, k):  # literal "level of f >= k", or True / False outside 1 .. levels
        if k <= 0:
            return True
        if k > levels:
            return False
        return ge[f] + k - 1

    def imply(premises, conclusion):  # premises: literals (True drops, False satisfies)
        lits = []
        for p in premises:
            if p is True:
                continue
            if p is False:
                return
            lits.append(-p)
        if conclusion is True:
            return
        if conclusion is not False:
            lits.append(conclusion)
        cnf.add(*lits)

    d_edge = {}
    for f, i, g, j in mesh.edges:
        if g < 0:
            cnf.add(-(t[f] + 3 * i + D))
            continue
        dp = cnf.var(3)
        d0, dm = dp + 1, dp + 2  # level of g = level of f + 1, + 0, - 1
        tf, tg = t[f] + 3 * i, t[g] + 3 * j
        cnf.add(-(tf + D), tg + D)
        cnf.add(-(tg + D), tf + D)
        cnf.add(-(tf + L1), -(tg + L0), dp)
        cnf.add(-(tf + L0), -(tg + L1), dm)
        cnf.add(-(tf + L0), -(tg + L0), d0)
        cnf.add(-(tf + L1), -(tg + L1), d0)
        cnf.add(-(tf + D), d0)
        for k in range(-1, levels + 2):
            # d0: ge_f[k] <-> ge_g[k]; dp: ge_f[k] <-> ge_g[k+1]; dm: ge_f[k] <-> ge_g[k-1]
            for delta, var in ((0, d0), (1, dp), (-1, dm)):
                imply([var, ge_lit(f, k)], ge_lit(g, k + delta))
                imply([var, ge_lit(g, k + delta)], ge_lit(f, k))
        d_edge[(f, i)] = (g, j)
        d_edge[(g, j)] = (f, i)
    # Angle sums: a chain of partial sums per vertex (p[j][s]: the first j corners sum to s).
    for v, cs in mesh.corners.items():
        total = target_sum(mesh, valence, v)
        n = len(cs)
        prev = {0: True}
        for step, (f, i) in enumerate(cs):
            left = n - step - 1
            cur = {}
            for s in range(step + 1, 4 * (step + 1) + 1):
                if total - 4 * left <= s <= total - left:
                    cur[s] = cnf.var()
            for s, ps in prev.items():
                for angle in range(1, 5):
                    imply([ps, a[f] + 4 * i + angle - 1], cur.get(s + angle, False))
            for s, cs_var in cur.items():
                preds = [prev[s - angle] for angle in range(1, 5) if s - angle in prev]
                if True not in preds:
                    cnf.add(-cs_var, *preds)
                cnf.add(-cs_var, *[a[f] + 4 * i + angle - 1 for angle in range(1, 5) if s - angle in prev])
            prev = cur
        if total not in prev:
            cnf.add()  # infeasible (cannot happen for a valid fan)
    if "ends" in extra or "corner" in extra:
        # A diagonal has 1 in both faces at one end and a 3 in at least one face at the other
        # (a bisection, or a closure's trapezoid halves); w: the both-1 end is the face's corner i+1.
        w_of = {}
        for f, i, g, j in mesh.edges:
            if g < 0:
                continue
            w = cnf.var()
            w_of[(f, i)] = w
            w_of[(g, j)] = -w  # g's corner j+1 is f's corner i+2
            Dv = t[f] + 3 * i + D
            fu, fv = (i + 1) % 3, (i + 2) % 3  # f's corners at u = faces[f][i+1], v = faces[f][i+2]
            gv, gu = (j + 1) % 3, (j + 2) % 3  # g runs v -> u
            one = lambda h, c: a[h] + 4 * c
            three = lambda h, c: a[h] + 4 * c + 2
            cnf.add(-Dv, -w, one(f, fu))
            cnf.add(-Dv, -w, one(g, gu))
            cnf.add(-Dv, -w, three(f, fv), three(g, gv))
            cnf.add(-Dv, w, one(f, fv))
            cnf.add(-Dv, w, one(g, gv))
            cnf.add(-Dv, w, three(f, fu), three(g, gu))
        if "corner" in extra:
            # A (1, 1, 4) face's side opposite the both-1 end of its diagonal is the closure's
            # corner triangle: red.
            for f in range(len(mesh.faces)):
                for c, l in ((0, 7), (1, 8), (2, 9)):  # the 4 at corner c; diagonal = side c
                    if (f, c) not in w_of:
                        cnf.add(-(x[f] + l))
                        continue
                    w = w_of[(f, c)]
                    for end, wl in (((c + 1) % 3, w), ((c + 2) % 3, -w)):
                        if (f, end) in d_edge:
                            g, _ = d_edge[(f, end)]
                            cnf.add(-(x[f] + l), -wl, x[g] + RED)
                        else:
                            cnf.add(-(x[f] + l), -wl)
    if "vlevels" in extra:
        # Vertex levels: 0 at base vertices only; an edge of level l (L_l, or a diagonal D_{l-1})
        # joins vertices of levels at most l, one of them exactly l.
        top = levels + 1
        vge = [cnf.var(top) for _ in range(mesh.nv)]  # vge[v] + k - 1: level of v >= k
        for v in range(mesh.nv):
            for k in range(1, top):
                cnf.add(-(vge[v] + k), vge[v] + k - 1)
            cnf.add(-vge[v] if v < len(valence) else vge[v])
        for f, i, g, j in mesh.edges:
            u, w = mesh.faces[f][(i + 1) % 3], mesh.faces[f][(i + 2) % 3]
            for types, o in (((L0,), 0), ((L1, D), 1)):
                for ty in types:
                    tl = t[f] + 3 * i + ty
                    for k in range(1, top + 2):
                        at_least = ge_lit(f, k - o)  # the edge's level is at least k
                        if k > top:
                            imply([tl, at_least], False)
                            continue
                        ends = (vge[u] + k - 1, vge[w] + k - 1)
                        if at_least is not False:  # one end at least k
                            cnf.add(-tl, *([] if at_least is True else [-at_least]), *ends)
                        if at_least is not True:  # else both ends below k
                            for end in ends:
                                cnf.add(-tl, -end, *([] if at_least is False else [at_least]))
        cnf.vge = vge
    if "anchor" in extra:
        cnf.add(*[-(ge[f]) for f in range(nf)])  # some face at level 0 (the labels fix levels up to a shift)
    if "chains" in extra:
        # Base edges: a flag per leaf edge; at a base vertex flagged edges every 2 (60 degrees), at
        # another vertex none or two 6 apart (a straight line), boundary edges flagged, no diagonal.
        flag = {}
        for f, i, g, j in mesh.edges:
            e = edge_key(mesh.faces[f][(i + 1) % 3], mesh.faces[f][(i + 2) % 3])
            flag[e] = cnf.var()
            cnf.add(-flag[e], -(t[f] + 3 * i + D))
            if g < 0:
                cnf.add(flag[e])
        cnf.flag = flag
        for v, (fan, edges) in mesh.fans.items():
            sep = 2 if v < len(valence) else 6
            n = len(fan)
            cyclic = len(edges) == n
            if v < len(valence):
                cnf.add(*[flag[e] for e in edges])
            q = [cnf.var(sep) for _ in range(len(edges))]  # q[k] + s: angle since the last flag, at edges[k]
            for k, e in enumerate(edges):
                cnf.add(-flag[e], q[k])
            for k, (f, i) in enumerate(fan):
                k2 = (k + 1) % n if cyclic else k + 1
                nxt = flag[edges[k2]]
                for s_ in range(sep):
                    for angle in range(1, 5):
                        prem = [-(q[k] + s_), -(a[f] + 4 * i + angle - 1)]
                        t_ = s_ + angle
                        if t_ < sep:
                            cnf.add(*prem, -nxt)
                            cnf.add(*prem, q[k2] + t_)
                        elif t_ == sep:
                            cnf.add(*prem, nxt)
                        else:
                            cnf.add(*prem)
    cnf.ge = ge
    cnf.levels = levels
    return cnf, x


def write_cnf(cnf, path, extra_clauses=()):
    with open(path, "w") as out:
        out.write("p cnf %d %d\n" % (cnf.n, len(cnf.clauses) + len(extra_clauses)))
        out.write("".join(" ".join(map(str, c)) + " 0\n" for c in cnf.clauses))
        for c in extra_clauses:
            out.write(" ".join(map(str, c)) + " 0\n")


def solve(path, timeout):
    start = time.time()
    r = subprocess.run(["cadical", "-q", "-t", str(timeout), path], capture_output=True, text=True)
    secs = time.time() - start
    status, model = None, set()
    for line in r.stdout.splitlines():
        if line.startswith("s "):
            status = line[2:].strip()
        elif line.startswith("v "):
            model.update(int(v) for v in line[2:].split() if int(v) > 0)
    return status or "UNKNOWN", model, secs


def labelling(x, model):
    return [next(l for l in range(10) if x[f] + l in model) for f in range(len(x))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("labels", help="a file written by angle_labels")
    ap.add_argument("--levels", type=int, default=None, help="highest face level allowed (default: the hierarchy's depth + 2)")
    ap.add_argument("--extra", default="", help="comma list of constraints beyond angle sums and edge lengths: "
                    "vlevels (vertex levels), ends (diagonal ends), corner (closure corner red), "
                    "chains (base edges straight, 60 degrees apart), anchor (some face at level 0)")
    ap.add_argument("--unique", action="store_true", help="solve again with the labelling found excluded")
    ap.add_argument("--truth-levels", type=float, default=0, metavar="SHARE",
                    help="give the solver the true levels of that share of the faces (random ones)")
    ap.add_argument("--truth-flags", action="store_true", help="give the solver the true base edges")
    ap.add_argument("--show", type=int, default=0, help="print that many faces where the second solution differs")
    ap.add_argument("--timeout", type=int, default=600)
    ap.add_argument("--seed", type=int, default=1, help="shuffle of faces and vertices")
    ap.add_argument("--cnf", default=None, help="where to write the CNF (default: a temporary file)")
    args = ap.parse_args()
    nv, faces, valence, depth, truth, level, root = read_labels(args.labels)
    # Shuffle so that the CNF's order tells nothing of the hierarchy's (base vertices keep their ids).
    rnd = random.Random(args.seed)
    order = list(range(len(faces)))
    if args.seed:
        rnd.shuffle(order)
    vmap = list(range(len(valence))) + (rnd.sample(range(len(valence), nv), nv - len(valence)) if args.seed else
                                        list(range(len(valence), nv)))
    faces = [tuple(vmap[v] for v in faces[f]) for f in order]
    truth = [truth[f] for f in order]
    level = [level[f] for f in order]
    root = [root[f] for f in order]
    mesh = Mesh(nv, faces)
    bad = check_truth(mesh, valence, truth, level)
    flags = true_flags(mesh, root)
    bad += check_chains(mesh, valence, truth, flags)
    if bad:
        print("truth violates the constraints:", len(bad), bad[:5])
        return 1
    t0 = time.time()
    cnf, x = build(mesh, valence, args.levels if args.levels is not None else depth + 2, set(args.extra.split(",")))
    if args.truth_levels:  # how far the true levels of a share of the faces take the solver
        for f in rnd.sample(range(len(faces)), round(args.truth_levels * len(faces))):
            for k in range(1, cnf.levels + 1):
                cnf.add(cnf.ge[f] + k - 1 if level[f] >= k else -(cnf.ge[f] + k - 1))
    if args.truth_flags and "chains" in args.extra:  # how far the truth's base edges alone take the solver
        for e in cnf.flag:
            cnf.add(cnf.flag[e] if e in flags else -cnf.flag[e])
    path = args.cnf or "/tmp/angle_sat_%d.cnf" % os.getpid()
    write_cnf(cnf, path)
    gen = time.time() - t0
    status, model, secs = solve(path, args.timeout)
    out = {"faces": len(faces), "vertices": nv, "depth": depth, "vars": cnf.n, "clauses": len(cnf.clauses),
           "gen_s": round(gen, 1), "status": status, "solve_s": round(secs, 2)}
    if status == "SATISFIABLE":
        found = labelling(x, model)
        diff = [f for f in range(len(faces)) if found[f] != truth[f]]
        out["differs_from_truth"] = len(diff)
        if args.show:
            lv = [sum(1 for k in range(cnf.levels) if cnf.ge[f] + k in model) for f in range(len(faces))]
            for f in range(min(len(faces), args.show)):
                print("  first: face %d %s truth %s level %d found %s level %d" % (f, faces[f], LABELS[truth[f]], level[f], LABELS[found[f]], lv[f]))
        if args.unique:
            block = [tuple(-(x[f] + found[f]) for f in range(len(faces)))]
            write_cnf(cnf, path, block)
            status2, model2, secs2 = solve(path, args.timeout)
            out["second"] = status2
            out["second_s"] = round(secs2, 2)
            if status2 == "SATISFIABLE":
                second = labelling(x, model2)
                d2 = [f for f in range(len(faces)) if second[f] != found[f]]
                out["second_differs_faces"] = len(d2)
                out["second_vs_truth"] = sum(second[f] != truth[f] for f in range(len(faces)))
                lv = [sum(1 for k in range(cnf.levels) if cnf.ge[f] + k in model2) for f in range(len(faces))]
                out["second_check"] = check_truth(mesh, valence, second, lv)[:4]
                if args.show:
                    for f in d2[:args.show]:
                        nb = [mesh.half.get((faces[f][(i + 2) % 3], faces[f][(i + 1) % 3]), (-1,))[0] for i in range(3)]
                        print("  face %d %s truth %s level %d second %s level %d; neighbours %s (differing: %s)" % (
                            f, faces[f], LABELS[truth[f]], level[f], LABELS[second[f]], lv[f], nb, [g for g in nb if g in set(d2)]))
    if not args.cnf:
        os.unlink(path)
    print(" ".join("%s=%s" % kv for kv in out.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
