// The saturated column of parameter_files/verification/semi_implicit_hydrostatic.prm
// made with gmsh: the grid 0.075 x 1.1 m of 3 x 44 square cells (0.025 m); the
// lower 40 rows (y < 1) form the surface "column" that talus-mesh fills with
// material points, the upper 4 are the dry head room. talus-semi-implicit keeps
// its box grid and reads only the particle file (body shape = file): the same
// points as the box body (tests/verification/check_semi_file_body.py).
W  = 0.075;
H  = 1.0;   // column
Hg = 1.1;   // grid
Point(1) = {0, 0, 0};
Point(2) = {W, 0, 0};
Point(3) = {W, H, 0};
Point(4) = {0, H, 0};
Point(5) = {W, Hg, 0};
Point(6) = {0, Hg, 0};
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
Transfinite Curve{1, 3, 6} = 4;
Transfinite Curve{2, 4} = 41;
Transfinite Curve{5, 7} = 5;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};

Physical Curve("boundary 0") = {4, 7};
Physical Curve("boundary 1") = {2, 5};
Physical Curve("boundary 2") = {1};
Physical Curve("boundary 3") = {6};
Physical Surface("column") = {1};
Physical Surface("head room") = {2};
