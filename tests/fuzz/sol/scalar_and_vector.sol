MeshVersionFormatted 2

Dimension 3

SolAtVertices
3
2 1 2
0.5 1 0 0
-0.25 0 1 0
1e-3 0 0 1

End
