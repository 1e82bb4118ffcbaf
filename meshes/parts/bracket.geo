// bracket.geo — an example mechanical part for the thermal shape-optimisation application
// (paper, section 4.4.3): a base plate with four bolt holes and an adjustment slot, and a
// bearing block standing on it with a cylindrical bore through it.  All edges are sharp.
//
// Part of bodyfit.  Copyright (c) 2026, the bodyfit developers.
// SPDX-License-Identifier: BSD-3-Clause (see LICENSE at the top of the repository).
//
// Written for gmsh 4.8 with the OpenCASCADE kernel (Debian 12: apt-get install gmsh).
// Surface mesh of size h, Medit format (the shipped meshes are made by
// scripts/make_bracket_meshes.sh, which also cleans and checks gmsh's output):
//
//     gmsh bracket.geo -2 -setnumber h 0.05 -format mesh -o bracket_raw.mesh
//
// Every parameter below can be set from the command line the same way (-setnumber name value).
//
// Axes: x along the plate length, y along its width, z up; the plate's lower front-left corner is
// the origin.  Topology: 4 bolt holes + 1 slot + 1 bore = genus 6 (Euler characteristic -10).

SetFactory("OpenCASCADE");

// ---- Parameters -------------------------------------------------------------------------------
DefineConstant[
  // mesh
  h = 0.07,       // target edge length of the triangles
  ncirc = 12,     // at least this many edges around a full circle (holes, bore); 0: uniform h
  // base plate
  L = 1.0,        // length (x)
  W = 0.6,        // width (y)
  T = 0.14,       // thickness (z)
  // bolt holes, one near each corner of the plate
  rb = 0.065,     // radius
  eb = 0.14,      // distance from the hole centres to the plate's sides
  // bearing block, centred in x, flush with the back side (y = W) of the plate
  BW = 0.4,       // width (x)
  BD = 0.24,      // depth (y)
  BH = 0.45,      // height above the plate (z)
  // bore through the block, along y
  R = 0.08,       // radius
  zb = 0.25,      // height of its axis above the plate's top face
  // slot through the plate, in front of the block: a stadium along x
  SL = 0.4,       // overall length (x)
  SW = 0.14       // width (y)
];

// ---- Solids -------------------------------------------------------------------------------------
e = 0.01 * L;                 // overlap of the cutting tools beyond the faces they cut through
xc = L / 2;                   // the part is symmetric about the plane x = xc
yb = W - BD;                  // front face of the block
ys = yb / 2;                  // axis of the slot: halfway between the front side and the block

Box(1) = {0, 0, 0, L, W, T};                            // plate
Box(2) = {xc - BW / 2, yb, T / 2, BW, BD, BH + T / 2};  // block, overlapping the plate for a clean union
body() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };

// cutting tools
Cylinder(10) = {xc, yb - e, T + zb, 0, BD + 2 * e, 0, R};   // bore
Cylinder(11) = {eb,     eb,     -e, 0, 0, T + 2 * e, rb};   // bolt holes
Cylinder(12) = {L - eb, eb,     -e, 0, 0, T + 2 * e, rb};
Cylinder(13) = {eb,     W - eb, -e, 0, 0, T + 2 * e, rb};
Cylinder(14) = {L - eb, W - eb, -e, 0, 0, T + 2 * e, rb};
Box(15) = {xc - SL / 2 + SW / 2, ys - SW / 2, -e, SL - SW, SW, T + 2 * e};  // slot: straight part
Cylinder(16) = {xc - SL / 2 + SW / 2, ys, -e, 0, 0, T + 2 * e, SW / 2};    // ... and round ends
Cylinder(17) = {xc + SL / 2 - SW / 2, ys, -e, 0, 0, T + 2 * e, SW / 2};

part() = BooleanDifference{ Volume{body()}; Delete; }{ Volume{10:17}; Delete; };

// ---- Mesh ---------------------------------------------------------------------------------------
// Triangles of size h everywhere except on the round surfaces (bolt holes, bore, round ends of the
// slot), where the size is reduced so that a full circle gets at least ncirc edges.  With size h
// alone a bolt hole would be a hexagon at h = 0.07 (8 or 9 sides at h = 0.05): neighbouring facets
// would meet at 40-60 degrees and pass for sharp edges in a feature-angle test (bodyfit's remesher
// flags ridges above 45 degrees).  With ncirc = 12 they meet at about 30 degrees.
// The round surfaces are found by bounding boxes that enclose them and no other face.
p = 1e-3;                                              // slack of the bounding boxes
hb = h;                                   // size on the bolt holes,
hr = h;                                   // ... on the bore,
hs = h;                                   // ... on the round ends of the slot
If (ncirc > 0)
  hb = Min(h, 2 * Pi * rb / ncirc);
  hr = Min(h, 2 * Pi * R / ncirc);
  hs = Min(h, Pi * SW / ncirc);           // the ends are half circles of radius SW/2
EndIf
bolt() = {};
For i In {0:1}
  For j In {0:1}
    x = eb + i * (L - 2 * eb);
    y = eb + j * (W - 2 * eb);
    bolt() += Surface In BoundingBox{x - rb - p, y - rb - p, -p, x + rb + p, y + rb + p, T + p};
  EndFor
EndFor
bore() = Surface In BoundingBox{xc - R - p, yb - p, T + zb - R - p, xc + R + p, W + p, T + zb + R + p};
ends() = Surface In BoundingBox{xc - SL / 2 - p, ys - SW / 2 - p, -p, xc - SL / 2 + SW / 2 + p, ys + SW / 2 + p, T + p};
ends() += Surface In BoundingBox{xc + SL / 2 - SW / 2 - p, ys - SW / 2 - p, -p, xc + SL / 2 + p, ys + SW / 2 + p, T + p};
If (#bolt() != 4 || #bore() != 1 || #ends() < 2)
  Error("bracket.geo: found %g bolt-hole, %g bore and %g slot-end faces (expected 4, 1, >= 2)", #bolt(), #bore(), #ends());
EndIf

// Size field: the minimum of h and of each reduced size restricted to its round faces and their rims.
Field[1] = MathEval; Field[1].F = Sprintf("%.17g", h);
Field[2] = MathEval; Field[2].F = Sprintf("%.17g", hb);
Field[3] = Restrict; Field[3].InField = 2; Field[3].SurfacesList = {bolt()};
Field[3].CurvesList = {Boundary{Surface{bolt()};}};
Field[4] = MathEval; Field[4].F = Sprintf("%.17g", hr);
Field[5] = Restrict; Field[5].InField = 4; Field[5].SurfacesList = {bore()};
Field[5].CurvesList = {Boundary{Surface{bore()};}};
Field[6] = MathEval; Field[6].F = Sprintf("%.17g", hs);
Field[7] = Restrict; Field[7].InField = 6; Field[7].SurfacesList = {ends()};
Field[7].CurvesList = {Boundary{Surface{ends()};}};
Field[8] = Min; Field[8].FieldsList = {1, 3, 5, 7};
Background Field = 8;

Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = Min(hb, Min(hr, hs));
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 1;   // grade the size from the small rims into the flat faces
Mesh.Algorithm = 6;                    // Frontal-Delaunay: best triangle shapes here (tried 1, 5, 6)
Mesh.Smoothing = 5;
Mesh.ElementOrder = 1;
