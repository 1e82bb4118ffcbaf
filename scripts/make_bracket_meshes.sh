#!/usr/bin/env bash
# Regenerate the surface meshes of the example mechanical part (meshes/parts/bracket.geo):
#   meshes/parts/bracket_h0.07.mesh, meshes/parts/bracket_h0.05.mesh
# with Debian 12's gmsh (OpenCASCADE kernel), then clean and check them (python3, standard library
# only): vertices and triangles only, plus the sharp feature curves as Edges + Ridges; every
# triangle at ref 2 (MMG: outside region S\G); closed, 2-manifold, one component, oriented
# outward; no duplicate or unused vertices. The script stops with an error when a check fails, and
# prints counts, genus and triangle quality for each mesh.
#
# Installs gmsh if it is missing (the normal build of bodyfit does not need it).
# usage: scripts/make_bracket_meshes.sh [h ...]      (default: 0.07 0.05)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GEO="$ROOT/meshes/parts/bracket.geo"
SIZES=("$@")
((${#SIZES[@]})) || SIZES=(0.07 0.05)

if ! dpkg-query -W -f='${Status}' gmsh 2>/dev/null | grep -q "install ok installed"; then
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  echo "make_bracket_meshes: installing gmsh"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends gmsh
fi
INFO=$(gmsh -info 2>&1 || true)
if ! grep -q "OpenCASCADE" <<<"$INFO"; then
  echo "make_bracket_meshes: this gmsh has no OpenCASCADE kernel (gmsh -info)" >&2
  exit 1
fi
echo "make_bracket_meshes: gmsh $(gmsh --version 2>&1), $(grep "^OCC version" <<<"$INFO" | tr -s ' ')"

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

cat >"$TMP/post.py" <<'PY'
"""Clean gmsh's Medit surface mesh of the bracket, check it, write it and report.

usage: post.py RAW.mesh OUT.mesh
"""
import math
import os
import sys
from collections import defaultdict

SHARP_DEG = 60.0   # a gmsh curve is a sharp feature curve when all its edges have at least this dihedral angle
FEATURE_DEG = 45.0  # ... and no other edge may be sharper than this (bodyfit's remesher's default feature angle)


def read_medit(path):
    tok = open(path).read().split()
    i, sec = 0, {}
    known = {"Vertices": 4, "Edges": 3, "Triangles": 4, "Quadrilaterals": 5, "Tetrahedra": 5,
             "Hexahedra": 9, "Prisms": 7, "Corners": 1, "Ridges": 1, "RequiredVertices": 1,
             "RequiredEdges": 1}
    while i < len(tok):
        w = tok[i]
        i += 1
        if w == "MeshVersionFormatted" or w == "Dimension":
            i += 1
        elif w == "End":
            break
        elif w in known:
            n, k = int(tok[i]), known[w]
            i += 1
            sec[w] = [tok[i + j * k:i + (j + 1) * k] for j in range(n)]
            i += n * k
        else:
            sys.exit(f"post: unexpected keyword {w!r} in {path}")
    return sec


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(a):
    return math.sqrt(dot(a, a))


def main():
    raw, out = sys.argv[1], sys.argv[2]
    sec = read_medit(raw)
    dropped = {k: len(v) for k, v in sec.items() if k not in ("Vertices", "Edges", "Triangles")}
    pts = [tuple(float(x) for x in r[:3]) for r in sec["Vertices"]]
    tris = [tuple(int(x) - 1 for x in r[:3]) for r in sec["Triangles"]]
    edges = [(int(r[0]) - 1, int(r[1]) - 1, int(r[2])) for r in sec.get("Edges", [])]

    # Duplicate vertices (same point, within 1e-9 of the part's size): merge them.
    scale = max(max(p[c] for p in pts) - min(p[c] for p in pts) for c in range(3))
    key = lambda p: tuple(round(c / (1e-9 * scale)) for c in p)
    first, alias = {}, list(range(len(pts)))
    for i, p in enumerate(pts):
        alias[i] = first.setdefault(key(p), i)
    n_dup = sum(1 for i in range(len(pts)) if alias[i] != i)
    tris = [tuple(alias[v] for v in t) for t in tris]
    edges = [(alias[a], alias[b], r) for a, b, r in edges]
    degenerate = [t for t in tris if len(set(t)) < 3]
    if degenerate:
        sys.exit(f"post: {len(degenerate)} degenerate triangles")
    if len({tuple(sorted(t)) for t in tris}) != len(tris):
        sys.exit("post: duplicate triangles")

    # Keep only the vertices used by triangles, renumbered in their order of appearance.
    new = {}
    for t in tris:
        for v in t:
            new.setdefault(v, len(new))
    order = sorted(new, key=new.get)
    pts = [pts[v] for v in order]
    tris = [tuple(new[v] for v in t) for t in tris]
    edges = [(new[a], new[b], r) for a, b, r in edges if a in new and b in new]
    n_unused = len(sec["Vertices"]) - n_dup - len(pts)

    # Edge -> triangles; closed and edge-manifold: every edge has exactly two triangles.
    e2t = defaultdict(list)
    for f, t in enumerate(tris):
        for k in range(3):
            a, b = t[k], t[(k + 1) % 3]
            e2t[(min(a, b), max(a, b))].append(f)
    bad = {e: fs for e, fs in e2t.items() if len(fs) != 2}
    if bad:
        n_b = sum(1 for fs in bad.values() if len(fs) == 1)
        sys.exit(f"post: {n_b} boundary edges, {len(bad) - n_b} non-manifold edges")

    # Consistent orientation (flip triangles breadth first), then outward (positive volume).
    def has_dir(t, a, b):
        return any(t[k] == a and t[(k + 1) % 3] == b for k in range(3))

    raw_tris = list(tris)
    tris = [list(t) for t in tris]
    seen, n_comp = [False] * len(tris), 0
    for s in range(len(tris)):
        if seen[s]:
            continue
        n_comp += 1
        seen[s], queue = True, [s]
        while queue:
            f = queue.pop()
            t = tris[f]
            for k in range(3):
                a, b = t[k], t[(k + 1) % 3]
                for g in e2t[(min(a, b), max(a, b))]:
                    if g == f:
                        continue
                    if not seen[g]:
                        if has_dir(tris[g], a, b):
                            tris[g].reverse()
                        seen[g] = True
                        queue.append(g)
                    elif has_dir(tris[g], a, b):
                        sys.exit("post: the surface is not orientable")
    if n_comp != 1:
        sys.exit(f"post: {n_comp} connected components")
    vol = sum(dot(pts[t[0]], cross(pts[t[1]], pts[t[2]])) for t in tris) / 6
    if vol < 0:
        tris = [t[::-1] for t in tris]
        vol = -vol
    tris = [tuple(t) for t in tris]
    n_flipped = sum(1 for t, r in zip(tris, raw_tris) if not any(t == r[k:] + r[:k] for k in range(3)))

    # Vertex-manifold: the triangles around each vertex form one fan (a single cycle).
    vt = defaultdict(list)
    for f, t in enumerate(tris):
        for k in range(3):
            vt[t[k]].append((t[(k + 1) % 3], t[(k + 2) % 3]))
    for v, fan in vt.items():
        nxt = dict(fan)
        if len(nxt) != len(fan):
            sys.exit(f"post: vertex {v + 1} is non-manifold")
        start, cur, steps = fan[0][0], nxt[fan[0][0]], 1
        while cur != start:
            cur, steps = nxt[cur], steps + 1
        if steps != len(fan):
            sys.exit(f"post: vertex {v + 1} is non-manifold (two fans)")

    # Dihedral angles; gmsh's curves (edge refs = curve tags) kept when sharp along their whole length.
    normal = []
    for t in tris:
        n = cross(sub(pts[t[1]], pts[t[0]]), sub(pts[t[2]], pts[t[0]]))
        normal.append(tuple(c / norm(n) for c in n))

    def dihedral(a, b):   # angle between the normals of the two triangles of edge a-b, in degrees
        f, g = e2t[(min(a, b), max(a, b))]
        return math.degrees(math.acos(max(-1.0, min(1.0, dot(normal[f], normal[g])))))

    curves = defaultdict(list)
    for a, b, r in edges:
        curves[r].append((a, b))
    sharp_edges, n_sharp_curves = [], 0
    for r, es in sorted(curves.items()):
        if min(dihedral(a, b) for a, b in es) >= SHARP_DEG:
            n_sharp_curves += 1
            sharp_edges += es
    sharp_set = {(min(a, b), max(a, b)) for a, b in sharp_edges}
    # every edge of the mesh sharper than FEATURE_DEG must be on a kept curve, and vice versa
    strong = {e for e in e2t if dihedral(*e) > FEATURE_DEG}
    if strong != sharp_set:
        sys.exit(f"post: {len(strong - sharp_set)} sharp edges off the feature curves, "
                 f"{len(sharp_set - strong)} feature edges not sharp")
    smooth_max = max((dihedral(*e) for e in e2t if e not in sharp_set), default=0.0)

    # Topology.
    V, E, F = len(pts), len(e2t), len(tris)
    chi = V - E + F
    genus = (2 - chi) // 2
    if genus < 3:
        sys.exit(f"post: genus {genus}, expected at least 3")

    # Quality q = 4 sqrt(3) area / (l1^2 + l2^2 + l3^2); edge lengths; area.
    qs, area = [], 0.0
    for t in tris:
        p, q_, r = (pts[v] for v in t)
        a2 = 0.5 * norm(cross(sub(q_, p), sub(r, p)))
        area += a2
        s = dot(sub(q_, p), sub(q_, p)) + dot(sub(r, q_), sub(r, q_)) + dot(sub(p, r), sub(p, r))
        qs.append(4 * math.sqrt(3) * a2 / s)
    lens = [norm(sub(pts[a], pts[b])) for a, b in e2t]
    lo = [min(p[c] for p in pts) for c in range(3)]
    hi = [max(p[c] for p in pts) for c in range(3)]

    with open(out, "w") as f:
        f.write("MeshVersionFormatted 2\n\nDimension 3\n\n")
        f.write(f"Vertices\n{V}\n")
        for p in pts:
            f.write(" ".join(f"{c + 0.0:.12g}" for c in p) + " 0\n")
        f.write(f"\nTriangles\n{F}\n")
        for t in tris:
            f.write(f"{t[0] + 1} {t[1] + 1} {t[2] + 1} 2\n")
        if sharp_edges:
            f.write(f"\nEdges\n{len(sharp_edges)}\n")
            for a, b in sharp_edges:
                f.write(f"{a + 1} {b + 1} 0\n")
            f.write(f"\nRidges\n{len(sharp_edges)}\n")
            for i in range(len(sharp_edges)):
                f.write(f"{i + 1}\n")
        f.write("\nEnd\n")

    qs_sorted = sorted(qs)
    print(f"{os.path.basename(out)}:")
    print(f"  gmsh output: {len(sec['Vertices'])} vertices, {len(sec.get('Edges', []))} edges on {len(curves)} curves, "
          f"{len(sec['Triangles'])} triangles; dropped sections: {dropped or 'none'}")
    print(f"  cleaned: {n_dup} duplicate and {n_unused} unused vertices removed")
    print(f"  vertices {V}, edges {E}, triangles {F}; Euler characteristic {chi}, genus {genus}")
    print(f"  closed, edge- and vertex-manifold, one component, oriented outward ({n_flipped} of gmsh's triangles reversed; volume {vol:.6f}, area {area:.6f})")
    print(f"  bounding box [{lo[0]:.4g}, {hi[0]:.4g}] x [{lo[1]:.4g}, {hi[1]:.4g}] x [{lo[2]:.4g}, {hi[2]:.4g}]")
    print(f"  sharp feature curves {n_sharp_curves} of {len(curves)} ({len(sharp_edges)} edges, written as Edges + Ridges); "
          f"largest dihedral angle elsewhere {smooth_max:.1f} deg")
    print(f"  quality q: min {qs_sorted[0]:.3f}, mean {sum(qs) / F:.3f}, 1st percentile {qs_sorted[F // 100]:.3f}, "
          f"below 0.3: {sum(q < 0.3 for q in qs)} ({100 * sum(q < 0.3 for q in qs) / F:.2f} %), "
          f"below 0.5: {sum(q < 0.5 for q in qs)}")
    print(f"  edge length: min {min(lens):.4f}, mean {sum(lens) / E:.4f}, max {max(lens):.4f}")


main()
PY

for h in "${SIZES[@]}"; do
  out="$ROOT/meshes/parts/bracket_h$h.mesh"
  rm -f "$TMP/raw.mesh"
  # -v 2: warnings and errors only
  gmsh "$GEO" -2 -setnumber h "$h" -format mesh -o "$TMP/raw.mesh" -v 2
  python3 "$TMP/post.py" "$TMP/raw.mesh" "$out"
done
