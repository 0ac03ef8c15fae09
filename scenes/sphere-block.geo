// Sphere on a block for the Gmsh reader: a half ball (radius 1, flat top)
// 0.01 above an elastic block, linear tets, refined near the contact point.
//
// Regenerate scenes/sphere-block.msh with:
//   gmsh -3 -format msh41 scenes/sphere-block.geo -o scenes/sphere-block.msh
// and its tet10 counterpart (tests/contact_quadratic.rs, the Hertz check of
// the links on curved second-order facets; Gmsh puts the mid-side nodes on
// the sphere) with:
//   gmsh -3 -order 2 -format msh41 scenes/sphere-block.geo \
//     -o tests/data/gmsh/sphere-block-tet10.msh
//
// Physical names follow the solver's `<body>.<face>` convention: they are
// used verbatim as body and set names.
SetFactory("OpenCASCADE");

gap = 0.01;
radius = 1.0;
zc = radius + gap;  // sphere centre

Box(1) = {-1.5, -1.5, -1.0, 3.0, 3.0, 1.0};  // block, top face at z = 0
Sphere(2) = {0, 0, zc, radius};
Box(3) = {-1.2, -1.2, zc, 2.4, 2.4, 1.2};  // removes the upper half
BooleanDifference{ Volume{2}; Delete; }{ Volume{3}; Delete; }

eps = 1e-3;
block_bottom() = Surface In BoundingBox{-2, -2, -1 - eps, 2, 2, -1 + eps};
block_top() = Surface In BoundingBox{-2, -2, -eps, 2, 2, eps};
sphere_top() = Surface In BoundingBox{-1.1, -1.1, zc - eps, 1.1, 1.1, zc + eps};
sphere_all() = Surface In BoundingBox{-1.1, -1.1, gap - eps, 1.1, 1.1, zc + eps};
sphere_curved() = sphere_all();
sphere_curved() -= sphere_top();

Physical Volume("block") = {1};
Physical Volume("sphere") = {2};
Physical Surface("block.bottom") = {block_bottom()};
Physical Surface("block.top") = {block_top()};
Physical Surface("sphere.top") = {sphere_top()};
Physical Surface("sphere.curved") = {sphere_curved()};

// Fine near the contact point, coarse elsewhere.
Field[1] = Ball;
Field[1].Radius = 0.35;
Field[1].Thickness = 0.4;
Field[1].XCenter = 0;
Field[1].YCenter = 0;
Field[1].ZCenter = gap / 2;
Field[1].VIn = 0.07;
Field[1].VOut = 0.4;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
