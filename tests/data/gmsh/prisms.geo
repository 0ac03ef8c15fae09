// Fixtures for tests/gmsh.rs: a 2 x 1 x 1 box of prisms (a triangulated
// bottom extruded in two layers), first and second order.
//   gmsh -3 -format msh41 prisms.geo -o prism6.msh
//   gmsh -3 -format msh41 -order 2 -string "Mesh.SecondOrderIncomplete = 1;" prisms.geo -o prism15.msh
Point(1) = {0, 0, 0, 1};
Point(2) = {2, 0, 0, 1};
Point(3) = {2, 1, 0, 1};
Point(4) = {0, 1, 0, 1};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 3;
Transfinite Curve{2, 4} = 2;
Transfinite Surface{1};
out[] = Extrude {0, 0, 1} { Surface{1}; Layers{2}; Recombine; };
Physical Volume("block") = {out[1]};
Physical Surface("block.bottom") = {1};
Physical Surface("block.top") = {out[0]};
Physical Surface("block.xmin") = {out[5]};
Physical Curve("block.edge") = {1};
