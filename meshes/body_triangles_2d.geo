// A body mesh of triangles (2D): a layered block with a sloping top, inside the
// grid of meshes/test_domain_2d.geo. Lower layer "material 1 sand"
// [0.1, 0.9] x [0.1, 0.3] (area 0.16), upper layer "material 2 clay" up to
// y = 0.5 at x = 0.9 and y = 0.7 at x = 0.1 (area 0.24); total area 0.4 m^2.
lc = 0.06;
Point(1) = {0.1, 0.1, 0, lc};
Point(2) = {0.9, 0.1, 0, lc};
Point(3) = {0.9, 0.3, 0, lc};
Point(4) = {0.1, 0.3, 0, lc};
Point(5) = {0.9, 0.5, 0, lc};
Point(6) = {0.1, 0.7, 0, lc};
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
Physical Surface("material 1 sand") = {1};
Physical Surface("material 2 clay") = {2};
Physical Surface("block") = {1, 2};
