#!/usr/bin/env python3
"""Write bar_4x1x1.mesh: the surface of the bar [0, 4] x [0, 1] x [0, 1] gridded 0.1 on every face
(each square split into two triangles, diagonals alternating), outward, all triangles at ref 2.

    python3 meshes/parts/bar.py > meshes/parts/bar_4x1x1.mesh
"""
import sys

SIZE = (4.0, 1.0, 1.0)
STEP = 0.1


def main():
    cells = [round(length / STEP) for length in SIZE]
    index, points, triangles = {}, [], []

    def vertex(ijk):
        if ijk not in index:
            index[ijk] = len(points) + 1
            points.append(tuple(ijk[k] * SIZE[k] / cells[k] for k in range(3)))
        return index[ijk]

    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for side in (0, cells[a]):
            for u in range(cells[b]):
                for v in range(cells[c]):
                    def at(uu, vv):
                        ijk = [0, 0, 0]
                        ijk[a], ijk[b], ijk[c] = side, uu, vv
                        return vertex(tuple(ijk))
                    quad = [at(u, v), at(u + 1, v), at(u + 1, v + 1), at(u, v + 1)]
                    # (u, v) -> (u+1, v) -> (u+1, v+1) turns counterclockwise seen from +e_a.
                    for tri in ([(0, 1, 2), (0, 2, 3)] if (u + v) % 2 else [(0, 1, 3), (1, 2, 3)]):
                        t = list(tri)
                        if side == 0:
                            t[1], t[2] = t[2], t[1]
                        triangles.append([quad[i] for i in t])
    out = sys.stdout
    out.write("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n%d\n" % len(points))
    for p in points:
        out.write("%.12g %.12g %.12g 0\n" % p)
    out.write("\nTriangles\n%d\n" % len(triangles))
    for t in triangles:
        out.write("%d %d %d 2\n" % tuple(t))
    out.write("\nEnd\n")


if __name__ == "__main__":
    main()
