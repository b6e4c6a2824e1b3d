// The grid of parameter_files/verification/elastic_column_gravity.prm made with
// gmsh: 0.0625 x 1.25 m, 1 x 20 square cells; the lower 16 cells (y < 1) form the
// surface "column" that talus-mesh fills with material points, the upper 4 are
// head room. Boundary ids as the box grid (0 = x-, 1 = x+, 2 = y-, 3 = y+).
W  = 0.0625;
H  = 1.0;   // column
Hg = 1.25;  // grid
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
Transfinite Curve{1, 3, 6} = 2;
Transfinite Curve{2, 4} = 17;
Transfinite Curve{5, 7} = 5;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};

Physical Curve("boundary 0") = {4, 7};
Physical Curve("boundary 1") = {2, 5};
Physical Curve("boundary 2") = {1};
Physical Curve("boundary 3") = {6};
Physical Surface("column") = {1};
Physical Surface("head room") = {2};
