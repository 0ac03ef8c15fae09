// Hertz line contact, plane strain, half model (x >= 0, symmetry at x = 0):
// a quarter disc of radius R = 1 (centre (0, 0, R + gap)) on a block 4R wide and
// 4R deep (the half of an 8R x 4R block), one hex8 layer of thickness t in y.
// Unstructured quads graded from hc at the first contact point to 0.25 R.
//
//   gmsh -3 -format msh41 -setnumber hc 0.005 scripts/peers/hertz-line.geo -o line.msh
//
// Physical names follow the solver's `<body>.<face>` convention.
SetFactory("Built-in");
DefineConstant[ hc = 0.02, t = 0.01, far = 0.25 ];
// A tiny initial gap, so that gmsh does not merge the bodies' first points.
gap = 1e-5;
R = 1.0;

// Block: x in [0, 4], z in [-4, 0] (top face z = 0).
Point(1) = {0, 0, 0, hc};
Point(2) = {4, 0, 0, far};
Point(3) = {4, 0, -4, far};
Point(4) = {0, 0, -4, far};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Quarter disc just above the block's origin, flat top through its centre.
Point(11) = {0, 0, gap, hc};
Point(12) = {R, 0, R + gap, far};
Point(13) = {0, 0, R + gap, far};
Circle(11) = {12, 13, 11};
Line(12) = {11, 13};
Line(13) = {13, 12};
Curve Loop(2) = {11, 12, 13};
Plane Surface(2) = {2};

// Size: hc within 2.5 b of the contact (b = 0.1 R), growing linearly to far.
Field[1] = Distance;
Field[1].PointsList = {1, 11};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hc;
Field[2].SizeMax = far;
Field[2].DistMin = 0.25 * R;
Field[2].DistMax = 0.25 * R + 10 * far;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

// Frontal-Delaunay (its quad variant, algorithm 8, crashes gmsh 4.8), then
// Blossom full-quad recombination: hexahedra only, for the solver and C3D8.
Mesh.Algorithm = 6;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;

ex1[] = Extrude {0, t, 0} { Surface{1}; Layers{1}; Recombine; };
ex2[] = Extrude {0, t, 0} { Surface{2}; Layers{1}; Recombine; };
// ex1: [0] back face, [1] volume, [2..5] sides from lines 1..4.
// ex2: [0] back face, [1] volume, [2..4] sides from curves 11..13.
Physical Volume("block") = {ex1[1]};
Physical Volume("cylinder") = {ex2[1]};
Physical Surface("block.top") = {ex1[2]};
Physical Surface("block.bottom") = {ex1[4]};
Physical Surface("block.symmetry") = {ex1[5]};
Physical Surface("block.front") = {1};
Physical Surface("block.back") = {ex1[0]};
Physical Surface("cylinder.curved") = {ex2[2]};
Physical Surface("cylinder.symmetry") = {ex2[3]};
Physical Surface("cylinder.top") = {ex2[4]};
Physical Surface("cylinder.front") = {2};
Physical Surface("cylinder.back") = {ex2[0]};
