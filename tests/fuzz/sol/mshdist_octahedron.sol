MeshVersionFormatted 2

Dimension 3

SolAtVertices
6
2 1 2 

0.5 1 0 0
0.25 -1 0 0
0 0 1 0
-0.125 0 -1 0
-1e-300 0 0 1
1.5 0 0 -1

End
