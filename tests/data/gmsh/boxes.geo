// Fixtures for tests/gmsh.rs: two boxes, 2 x 1 x 1 cells each, with dyadic
// node coordinates so ASCII and binary files hold exactly the same numbers.
//   gmsh -3 -format msh41 -setnumber hex 1 boxes.geo -o hex.msh
//   gmsh -3 -format msh41 -bin -setnumber hex 1 boxes.geo -o hex-bin.msh
//   gmsh -3 -format msh41 -setnumber hex 0 boxes.geo -o tet.msh
//   gmsh -3 -format msh41 -bin -setnumber hex 0 boxes.geo -o tet-bin.msh
SetFactory("OpenCASCADE");
DefineConstant[ hex = 1 ];
Box(1) = {0, 0, 0, 2, 1, 1};
Box(2) = {0, 0, 1.5, 2, 1, 1};
Transfinite Curve{:} = 2;
Transfinite Curve{Curve In BoundingBox{-0.1, -0.1, -0.1, 2.1, 0.1, 2.6}} = 3;
Transfinite Curve{Curve In BoundingBox{-0.1, 0.9, -0.1, 2.1, 1.1, 2.6}} = 3;
Transfinite Surface{:};
If (hex)
  Recombine Surface{:};
EndIf
Transfinite Volume{:};
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
Physical Surface("lower.bottom") = {Surface In BoundingBox{-0.1, -0.1, -0.1, 2.1, 1.1, 0.1}};
Physical Surface("lower.top") = {Surface In BoundingBox{-0.1, -0.1, 0.9, 2.1, 1.1, 1.1}};
Physical Surface("upper.bottom") = {Surface In BoundingBox{-0.1, -0.1, 1.4, 2.1, 1.1, 1.6}};
Physical Curve("lower.edge") = {Curve In BoundingBox{-0.1, -0.1, -0.1, 2.1, 0.1, 0.1}};
Physical Point("lower.origin") = {Point In BoundingBox{-0.1, -0.1, -0.1, 0.1, 0.1, 0.1}};
