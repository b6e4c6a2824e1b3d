// 2D oedometer column (plane strain): W x H, nx x ny structured quadrangles,
// axis-aligned (what the MPM solvers need). Boundary ids follow the box-grid
// numbering of talus (0 = x-, 1 = x+, 2 = y-, 3 = y+), so the same
// 'boundary conditions' entries work for the box and the gmsh grid.
// Used by parameter_files/mesh/oedometer_2d.prm (talus-mesh).
W  = 0.1;
H  = 1.0;
nx = 2;
ny = 20;

Point(1) = {0, 0, 0};
Point(2) = {W, 0, 0};
Point(3) = {W, H, 0};
Point(4) = {0, H, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};

Physical Curve("boundary 0 left")  = {4};
Physical Curve("boundary 1 right") = {2};
Physical Curve("boundary 2 base")  = {1};
Physical Curve("boundary 3 top")   = {3};
Physical Surface("material 0 soil") = {1};
Physical Surface("column") = {1};
