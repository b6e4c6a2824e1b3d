// Test grid for talus-mesh (tests/verification/mesh.cmake): [0, 1] x [0, 1] in
// two transfinite blocks of 10 x 4 and 10 x 6 square cells (h = 0.1).
// Physical groups: every naming form talus-mesh understands --
//   "boundary 1 base"     boundary id 1 by the naming convention
//   tag 7 (unnamed)       the left side x = 0: boundary id 7 by its tag
//   "right"               a plain name: mapped in the .prm (boundary groups = right = 5)
//   "boundary 4"          the top
//   "material 1 sand"     lower block (40 cells)
//   "clay"                upper block (60 cells), mapped (material groups = clay = 2)
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 0.4, 0};
Point(4) = {0, 0.4, 0};
Point(5) = {1, 1, 0};
Point(6) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {3, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(2) = {2};
Transfinite Curve{1, 3, 6} = 11;
Transfinite Curve{2, 4} = 5;
Transfinite Curve{5, 7} = 7;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};

Physical Curve("boundary 1 base") = {1};
Physical Curve(7) = {4, 7};
Physical Curve("right") = {2, 5};
Physical Curve("boundary 4") = {6};
Physical Surface("material 1 sand") = {1};
Physical Surface("clay") = {2};
